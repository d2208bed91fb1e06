"""SIGINT and SIGTERM for `sitl-emu`, from its first line to its last.

PX4 SITL ends on either signal alike (platforms/posix/src/px4/common/main.cpp: register_sig_handler points both at
one handler, which prints "PX4 Exiting..." and stops everything) and installs that handler whatever it inherited, so
a PX4 started in the background by a script, whose shell set SIGINT to be ignored, still ends on `kill -INT`.

sitl-emu does the same, and from its entry point on (sitl_emu/__main__.py), before its imports: until the command
is known, a signal is only noted. `serve` then owns both (`owning_signals`): a signal noted or received before its loop
runs means the loop never starts, and after that it stops the loop; either way the vehicles are closed in order and
PX4's "PX4 Exiting..." is printed. Any other command gets the handling it inherited back (`release`), and a signal
noted meanwhile acts then. This module imports nothing of sitl_emu: it must be quick to load.
"""

from __future__ import annotations

import functools
import signal
from collections.abc import Callable
from types import FrameType
from typing import Any, TypeVar

HANDLED = (signal.SIGINT, signal.SIGTERM)
R = TypeVar("R")


class ShutdownSignals:
    """Notes SIGINT and SIGTERM in `received` and calls the stop function once one is given."""

    def __init__(self) -> None:
        self.received: list[int] = []
        self._stop: Callable[[], None] | None = None
        self._inherited: dict[int, Any] = {}

    @property
    def installed(self) -> bool:
        return bool(self._inherited)

    def install(self) -> None:
        """Handle both signals here from now on, whatever the process inherited (SIG_IGN included)."""
        for sig in HANDLED:
            self._inherited.setdefault(sig, signal.getsignal(sig))
            signal.signal(sig, self._on_signal)

    def _on_signal(self, signum: int, frame: FrameType | None) -> None:
        self.received.append(signum)
        if self._stop is not None:
            self._stop()

    def stop_with(self, stop: Callable[[], None]) -> None:
        """Call `stop` on a signal; at once if one has come already."""
        self._stop = stop
        if self.received:
            stop()

    def restore(self) -> None:
        """The handling the process had before `install`; what was received is forgotten."""
        for sig, handler in self._inherited.items():
            signal.signal(sig, handler)
        self._inherited.clear()
        self._stop = None
        self.received = []

    def release(self) -> None:
        """For a command other than `serve`: the inherited handling again; a signal noted meanwhile acts now, as it
        would have on arrival (ignored if it was ignored)."""
        noted, self.received = self.received, []
        self.restore()
        for sig in noted:
            signal.raise_signal(sig)


EARLY = ShutdownSignals()  # installed by the entry point before anything else is imported


def owning_signals(command: Callable[..., R]) -> Callable[..., R]:
    """Run `command(..., signals=EARLY)` owning both signals (installed now if the entry point did not, as when a
    test runs the command in-process), with what was noted before; the handling it found afterwards."""

    @functools.wraps(command)
    def run(*args: Any, **kwargs: Any) -> R:
        EARLY.install()
        try:
            return command(*args, signals=EARLY, **kwargs)
        finally:
            EARLY.restore()

    return run
