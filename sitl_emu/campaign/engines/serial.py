"""The serial engine: every case in this process, one after another (tracebacks and debuggers work as usual).

The wall-time limit is SIGALRM where there is one (POSIX, in the main thread): it interrupts the case wherever it is.
Elsewhere (Windows, another thread) the case's Sim checks the deadline before each step (scenario.run_case), so a
case stuck outside the Sim is not stopped there. A case that kills its process kills the campaign here: use the
local engine for such cases.
"""

from __future__ import annotations

import contextlib
import signal
import threading
import time
from collections.abc import Iterator, Sequence
from typing import Any

from sitl_emu.campaign.cases import Case
from sitl_emu.campaign.scenario import Limits, Row, WallTimeLimit, failure_row, run_case

__all__ = ["SerialEngine"]


class SerialEngine:
    def run(self, ref: str, cases: Sequence[Case], limits: Limits) -> Iterator[tuple[Case, Row]]:
        for case in cases:
            start = time.perf_counter()
            try:
                with _alarm(limits.wall_s) as deadline_s:
                    row = run_case(ref, case, limits, deadline_s)
            except WallTimeLimit:
                row = failure_row("timeout", f"the case passed its limit of {limits.wall_s:g} wall seconds.")
                row.update(sim_s=None, wall_s=round(time.perf_counter() - start, 3))
            yield case, row


def alarm_available() -> bool:
    """The seam: can SIGALRM end the case here (POSIX, the main thread)?"""
    main_thread = threading.current_thread() is threading.main_thread()
    return hasattr(signal, "setitimer") and hasattr(signal, "SIGALRM") and main_thread


@contextlib.contextmanager
def _alarm(seconds: float | None) -> Iterator[float | None]:
    """SIGALRM after `seconds` (yields None); where there is none, yields the deadline for the Sim's steps."""
    if seconds is None:
        yield None
        return
    if not alarm_available():
        yield time.perf_counter() + seconds
        return

    def expire(signum: int, frame: Any) -> None:
        raise WallTimeLimit

    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield None
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
