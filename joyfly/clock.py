"""Clocks for joyfly (the `joyfly.types.Clock` protocol): the wall clock, and the wall clock sped up.

The flight session reads time only through its clock, so a test can run a whole flight in simulated time
(tests/support/joyfly_sim.py SimClock).
"""

from __future__ import annotations

import time


class WallClock:
    """Monotonic wall time in seconds."""

    def now(self) -> float:
        return time.monotonic()

    def sleep(self, seconds: float) -> None:
        if seconds > 0:
            time.sleep(seconds)


class ScaledClock:
    """Wall time running `speed` times faster: pairs with an emulator running at the same speed factor, so every
    joyfly timeout and rate (and a script joystick's timing) follows the vehicle's simulated time."""

    def __init__(self, speed: float = 1.0) -> None:
        self.speed = speed
        self._t0 = time.monotonic()

    def now(self) -> float:
        return (time.monotonic() - self._t0) * self.speed

    def sleep(self, seconds: float) -> None:
        if seconds > 0:
            time.sleep(seconds / self.speed)
