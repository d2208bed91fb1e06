"""Clocks for a program that reads time only through a clock (`now()` in seconds, `sleep(seconds)`): the wall clock,
and the wall clock sped up to pair with an emulator run at `--speed`.

joyfly's flight session and sitl_emu's scripted test client both take one, so the same flight runs in wall time, in
scaled wall time beside `sitl-emu serve --speed N`, or in a simulation's own time (sitl_emu.testing.sim's
LockstepClock, tests/support/joyfly_sim.py's SimClock).
"""

from __future__ import annotations

import time

# --speed of both command lines (`sitl-emu serve`, `joyfly fly`/`demo`): simulated seconds per wall second. Below 0.1
# nothing is worth watching; above 100 neither the emulator (about 90 simulated s per CPU s with its I/O, README) nor
# a client keeps up.
SPEED_MIN, SPEED_MAX = 0.1, 100.0


class WallClock:
    """Monotonic wall time in seconds."""

    def now(self) -> float:
        return time.monotonic()

    def sleep(self, seconds: float) -> None:
        if seconds > 0:
            time.sleep(seconds)


class ScaledClock:
    """Wall time running `speed` times faster, from 0 at creation: paired with an emulator running at the same speed
    factor, every timeout and rate of its client (and a script joystick's timing) follows the simulated time."""

    def __init__(self, speed: float = 1.0) -> None:
        self.speed = float(speed)
        self._t0 = time.monotonic()

    def now(self) -> float:
        return (time.monotonic() - self._t0) * self.speed

    def sleep(self, seconds: float) -> None:
        if seconds > 0:
            time.sleep(seconds / self.speed)
