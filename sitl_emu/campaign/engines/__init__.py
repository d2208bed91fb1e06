"""Where the cases run: `serial` (this process, one after another: for rerunning one case under a debugger),
`local` (a pool of worker processes on this machine, the default) and `ray` (a Ray cluster, the ray extra).

Every engine runs `scenario.run_case` for each case and yields (case, row) as cases finish, in any order; a case
that passes its wall-time limit or whose worker dies is yielded as that case's failure and the others go on.
"""

from __future__ import annotations

import os
from collections.abc import Iterator, Sequence
from typing import Protocol

from sitl_emu.campaign.cases import Case
from sitl_emu.campaign.errors import CampaignError
from sitl_emu.campaign.scenario import Limits, Row

__all__ = ["ENGINES", "Engine", "default_workers", "make_engine"]

ENGINES = ("local", "ray", "serial")


class Engine(Protocol):
    def run(self, ref: str, cases: Sequence[Case], limits: Limits) -> Iterator[tuple[Case, Row]]: ...


def default_workers() -> int:
    """One worker per core this process may use: its CPU affinity where the OS tells it (Linux), else
    os.process_cpu_count (Python 3.13+, the same where it can be known), else every core (macOS, Windows)."""
    affinity = getattr(os, "sched_getaffinity", None)
    if affinity is not None:
        return max(1, len(affinity(0)))
    counted = getattr(os, "process_cpu_count", os.cpu_count)
    return max(1, counted() or 1)


def make_engine(name: str, workers: int | None = None, address: str | None = None) -> Engine:
    if name == "serial":
        from sitl_emu.campaign.engines.serial import SerialEngine

        return SerialEngine()
    if name == "local":
        from sitl_emu.campaign.engines.local import LocalEngine

        return LocalEngine(workers or default_workers())
    if name == "ray":
        from sitl_emu.campaign.engines.ray_engine import RayEngine

        return RayEngine(address, workers)
    raise CampaignError(f"unknown engine '{name}'; use one of {', '.join(ENGINES)}.")
