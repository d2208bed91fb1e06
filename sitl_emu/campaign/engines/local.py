"""The local engine: `workers` processes on this machine, each flying one case at a time.

Not concurrent.futures: its pool cannot stop one hanging task, and one dead worker breaks the whole pool. Here each
worker is a process with its own pipe; the parent waits on every pipe and every process sentinel at once, so a case
past its wall-time limit is killed with its worker, a worker that dies (os._exit, a segfault, the OOM killer) is that
case's failure, and a fresh worker takes the next case. Workers start with `spawn`: a clean interpreter, the same on
every platform, and no state shared with the parent but the case it is sent.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import signal
import time
from collections import deque
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from multiprocessing.connection import Connection, wait
from typing import Any

from sitl_emu.campaign.cases import Case
from sitl_emu.campaign.errors import CampaignError
from sitl_emu.campaign.scenario import Limits, Row, failure_row, prepare_worker, run_case

__all__ = ["LocalEngine"]

STOP_WAIT_S = 5.0
READY = "ready"


def _serve(conn: Connection, ref: str) -> None:
    """A worker's loop: "ready" once its imports and start-up are done (scenario.prepare_worker: they do not count
    in a case's wall time), then (ref, case, limits) in, the row out; None ends it. Ctrl-C is the parent's to
    handle."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    prepare_worker(ref)
    conn.send(READY)
    while True:
        try:
            job = conn.recv()
        except (EOFError, KeyboardInterrupt):
            return
        if job is None:
            return
        conn.send(run_case(*job))


@dataclass
class _Busy:
    case: Case
    started: float


class _Worker:
    def __init__(self, context: Any, ref: str) -> None:
        self.conn, child = context.Pipe()
        self.process = context.Process(target=_serve, args=(child, ref), daemon=True, name="sitl-emu-campaign")
        self.process.start()
        child.close()
        self.ready = False
        self.busy: _Busy | None = None

    def poll_ready(self) -> None:
        """Note the worker's "ready"; CampaignError if it died before (it cannot start: no case is to blame)."""
        if self.ready:
            return
        try:
            if self.conn.poll():
                self.ready = self.conn.recv() == READY
                return
        except (EOFError, OSError):
            self.process.join(STOP_WAIT_S)
        if not self.process.is_alive():
            raise CampaignError(f"a worker process could not start (exit code {self.process.exitcode}).")

    def give(self, ref: str, case: Case, limits: Limits) -> None:
        self.conn.send((ref, case, limits))
        self.busy = _Busy(case, time.monotonic())

    def stop(self, wait_s: float = STOP_WAIT_S) -> None:
        if self.process.is_alive() and self.busy is None:
            with contextlib.suppress(OSError):
                self.conn.send(None)
            self.process.join(wait_s)
        if self.process.is_alive():
            self.process.kill()
            self.process.join(wait_s)
        self.conn.close()


class LocalEngine:
    """A pool of `workers` processes (default: one per core)."""

    def __init__(self, workers: int, start_method: str = "spawn") -> None:
        self.workers = max(1, workers)
        self.context = multiprocessing.get_context(start_method)

    def run(self, ref: str, cases: Sequence[Case], limits: Limits) -> Iterator[tuple[Case, Row]]:
        pending = deque(cases)
        pool = [_Worker(self.context, ref) for _ in range(min(self.workers, len(pending)))]
        try:
            while pending or any(w.busy for w in pool):
                for index, worker in enumerate(pool):
                    result = _collect(worker, limits)
                    if result is None:
                        continue
                    yield result
                    if not worker.process.is_alive():
                        worker.stop()
                        pool[index] = _Worker(self.context, ref) if pending else worker
                for worker in pool:  # after collecting: a worker that just finished gets its next case before _wait
                    worker.poll_ready()
                    if worker.ready and worker.busy is None and pending:
                        worker.give(ref, pending.popleft(), limits)
                _wait(pool, limits)
        finally:
            for worker in pool:
                worker.stop(0.5)


def _collect(worker: _Worker, limits: Limits) -> tuple[Case, Row] | None:
    """The case `worker` finished, failed (its process died) or overran (killed here); None while it still runs."""
    busy = worker.busy
    if busy is None:
        return None
    elapsed = time.monotonic() - busy.started
    if worker.conn.poll():
        try:
            row = worker.conn.recv()
        except (EOFError, OSError):
            row = _died(worker, elapsed)
    elif not worker.process.is_alive():
        row = _died(worker, elapsed)
    elif limits.wall_s is not None and elapsed > limits.wall_s:
        worker.process.kill()
        worker.process.join(STOP_WAIT_S)
        row = failure_row("timeout", f"the case passed its limit of {limits.wall_s:g} wall seconds; its worker "
                                     "was stopped.")
        row.update(sim_s=None, wall_s=round(elapsed, 3))
    else:
        return None
    worker.busy = None
    return busy.case, row


def _died(worker: _Worker, elapsed: float) -> Row:
    worker.process.join(STOP_WAIT_S)
    code = worker.process.exitcode
    row = failure_row("crashed", f"the worker process died (exit code {code}) while flying this case.")
    row.update(sim_s=None, wall_s=round(elapsed, 3))
    return row


def _wait(pool: list[_Worker], limits: Limits) -> None:
    """Sleep until a worker answers (a row, or ready) or dies, or the next wall-time limit falls due."""
    busy = [w for w in pool if w.busy is not None]
    starting = [w for w in pool if not w.ready and w.process.is_alive()]
    if not busy and not starting:
        return
    timeout = None
    if limits.wall_s is not None and busy:
        first = min(w.busy.started for w in busy if w.busy is not None)
        timeout = max(0.0, first + limits.wall_s - time.monotonic()) + 0.01
    watched = busy + starting
    wait([w.conn for w in watched] + [w.process.sentinel for w in watched], timeout)
