"""The Ray engine (the `ray` extra: `pip install -e '.[ray]'` in the clone): each case a Ray task.

`address` joins an existing cluster (`ray start --head` printed it; "auto" finds a local one); without it a local
Ray is started for the campaign and shut down after it. The scenario must be importable on every node (a shared
filesystem, an installed package, or Ray's runtime_env). At most one task per CPU of the cluster is in flight, so a
task's wall time counts from when it starts; one past its limit is cancelled with its worker (ray.cancel force), and
a worker that dies is that case's failure: tasks are never retried, a retry would hide it.

Joining a cluster from `ray start --head` was tried here with Ray 2.60 by the node's address (the one `ray start`
prints) and RAY_AUTH_MODE=disabled on both sides; by 127.0.0.1 with Ray's default token authentication the driver
did not connect (not investigated further).
"""

from __future__ import annotations

import socket
import time
from collections.abc import Iterator, Sequence
from typing import Any

from sitl_emu.campaign.cases import Case
from sitl_emu.campaign.errors import CampaignError
from sitl_emu.campaign.scenario import Limits, Row, failure_row, one_line, prepare_worker, run_case
from sitl_emu.cli.extras import install_command

__all__ = ["RayEngine"]

PRELOAD_HOLD_S = 0.2
PROBE_TIMEOUT_S = 5.0
RAY_PACKAGES = "'ray>=2.9'"  # the ray extra (pyproject.toml), where joyfly does not run from a clone


def _ray() -> Any:
    try:
        import ray
    except ImportError:
        raise CampaignError("the ray engine needs Ray, which is not installed: "
                            f"{install_command('ray', RAY_PACKAGES)}, or use --engine local.") from None
    return ray


class RayEngine:
    def __init__(self, address: str | None = None, workers: int | None = None) -> None:
        """Checks at once that Ray is installed and that a HOST:PORT `address` answers; joins or starts it later."""
        _ray()
        if address:
            _probe(address)
        self.address = address
        self.workers = workers

    def run(self, ref: str, cases: Sequence[Case], limits: Limits) -> Iterator[tuple[Case, Row]]:
        ray = _ray()
        started_here = not ray.is_initialized()
        if started_here:
            self._init(ray)
        try:
            yield from self._run(ray, ref, cases, limits)
        finally:
            if started_here:
                ray.shutdown()

    def _init(self, ray: Any) -> None:
        options: dict[str, Any] = {"include_dashboard": False, "log_to_driver": True}
        if self.address:
            options["address"] = self.address
        elif self.workers:
            options["num_cpus"] = self.workers
        try:
            ray.init(**options)
        except (ConnectionError, RuntimeError, ValueError) as err:
            raise CampaignError(f"cannot start or join Ray{' at ' + self.address if self.address else ''}: "
                                f"{one_line(err)}") from None

    def _run(self, ray: Any, ref: str, cases: Sequence[Case], limits: Limits) -> Iterator[tuple[Case, Row]]:
        task = ray.remote(max_retries=0)(run_case)
        slots = self.workers or max(1, int(ray.cluster_resources().get("CPU", 1)))
        ray.get([ray.remote(max_retries=0)(_preload).remote(ref) for _ in range(min(slots, len(cases)))])
        pending = list(reversed(cases))
        running: dict[Any, tuple[Case, float]] = {}
        while pending or running:
            while pending and len(running) < slots:
                case = pending.pop()
                running[task.remote(ref, case, limits)] = (case, time.monotonic())
            done, _ = ray.wait(list(running), num_returns=1, timeout=_next_deadline(running, limits))
            for obj in done:
                case, started = running.pop(obj)
                yield case, _result(ray, obj, started)
            for obj in _overdue(running, limits):
                case, started = running.pop(obj)
                ray.cancel(obj, force=True)
                row = failure_row("timeout", f"the case passed its limit of {limits.wall_s:g} wall seconds; its "
                                             "Ray task was cancelled.")
                row.update(sim_s=None, wall_s=round(time.monotonic() - started, 3))
                yield case, row


def _probe(address: str) -> None:
    """A HOST:PORT nobody listens on fails here in one sentence (Ray itself retries for minutes, logging each try);
    "auto" and ray:// addresses are left to Ray."""
    host, sep, port = address.rpartition(":")
    if not sep or "://" in address or not port.isdigit():
        return
    try:
        socket.create_connection((host, int(port)), timeout=PROBE_TIMEOUT_S).close()
    except OSError as err:
        raise CampaignError(f"no Ray cluster answers at {address} ({err.strerror or err}); start one with "
                            "`ray start --head` or leave out --address to start Ray here.") from None


def _preload(ref: str) -> None:
    """A Ray worker's start-up (scenario.prepare_worker) before the first case's wall time starts; the short sleep
    keeps the worker busy so that the next of these lands on another worker."""
    prepare_worker(ref)
    time.sleep(PRELOAD_HOLD_S)


def _result(ray: Any, obj: Any, started: float) -> Row:
    try:
        row: Row = ray.get(obj)
        return row
    except ray.exceptions.WorkerCrashedError:
        row = failure_row("crashed", "the Ray worker died while flying this case.")
    except ray.exceptions.RayError as err:
        row = failure_row("crashed", f"Ray lost this case: {one_line(err).splitlines()[0][:200]}")
    row.update(sim_s=None, wall_s=round(time.monotonic() - started, 3))
    return row


def _next_deadline(running: dict[Any, tuple[Case, float]], limits: Limits) -> float | None:
    if limits.wall_s is None or not running:
        return None
    first = min(started for _, started in running.values())
    return max(0.0, first + limits.wall_s - time.monotonic()) + 0.01


def _overdue(running: dict[Any, tuple[Case, float]], limits: Limits) -> list[Any]:
    if limits.wall_s is None:
        return []
    now = time.monotonic()
    return [obj for obj, (_, started) in running.items() if now - started > limits.wall_s]
