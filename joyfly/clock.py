"""Clocks for joyfly (the `joyfly.types.Clock` protocol): the wall clock, and a simulated clock for tests.

The flight session reads time only through one of these, so a test can run a whole flight in simulated time.
"""

from __future__ import annotations

import time
from collections.abc import Callable


class WallClock:
    """Monotonic wall time in seconds."""

    def now(self) -> float:
        return time.monotonic()

    def sleep(self, seconds: float) -> None:
        if seconds > 0:
            time.sleep(seconds)


class SimClock:
    """Simulated time: `sleep` advances `now` at once and runs the registered hooks.

    Hooks (`on_advance(now_s)`) let a test step a simulated vehicle in lockstep with the session. A sleep longer
    than `max_step_s` is cut into steps of at most that length, so hooks see a fine-grained time line.
    """

    def __init__(self, start_s: float = 0.0, max_step_s: float = 0.01) -> None:
        self._now_s = start_s
        self._max_step_s = max_step_s
        self._hooks: list[Callable[[float], None]] = []

    def now(self) -> float:
        return self._now_s

    def on_advance(self, hook: Callable[[float], None]) -> None:
        self._hooks.append(hook)

    def sleep(self, seconds: float) -> None:
        if seconds <= 0:
            return
        target = self._now_s + seconds
        while self._now_s < target:
            self._now_s = min(target, self._now_s + self._max_step_s)
            for hook in self._hooks:
                hook(self._now_s)


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
