"""Where the cases run: `serial` (this process, one after another: for rerunning one case under a debugger),
`local` (a pool of worker processes on this machine, the default) and `ray` (a Ray cluster, the extra sitl-emu[ray]).

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
    """One worker per core this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return max(1, os.cpu_count() or 1)


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
