"""The serial engine: every case in this process, one after another (tracebacks and debuggers work as usual).

The wall-time limit needs SIGALRM (POSIX, main thread); elsewhere only the simulated-time limit applies. A case that
kills its process kills the campaign here: use the local engine for such cases.
"""

from __future__ import annotations

import contextlib
import signal
import threading
import time
from collections.abc import Iterator, Sequence
from typing import Any

from sitl_emu.campaign.cases import Case
from sitl_emu.campaign.scenario import Limits, Row, failure_row, run_case

__all__ = ["SerialEngine"]


class WallTimeLimit(BaseException):
    """Raised by SIGALRM in the case that passed its wall-time limit."""


class SerialEngine:
    def run(self, ref: str, cases: Sequence[Case], limits: Limits) -> Iterator[tuple[Case, Row]]:
        for case in cases:
            start = time.perf_counter()
            try:
                with _alarm(limits.wall_s):
                    row = run_case(ref, case, limits)
            except WallTimeLimit:
                row = failure_row("timeout", f"the case passed its limit of {limits.wall_s:g} wall seconds.")
                row.update(sim_s=None, wall_s=round(time.perf_counter() - start, 3))
            yield case, row


@contextlib.contextmanager
def _alarm(seconds: float | None) -> Iterator[None]:
    main_thread = threading.current_thread() is threading.main_thread()
    if seconds is None or not hasattr(signal, "setitimer") or not main_thread:
        yield
        return

    def expire(signum: int, frame: Any) -> None:
        raise WallTimeLimit

    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
