"""Does the vehicle's clock run at joyfly's --speed? A check from the vehicle's own timestamps.

The vehicle stamps its telemetry (ATTITUDE, LOCAL_POSITION_NED, SYSTEM_TIME, ...) with `time_boot_ms`, its time
since boot: simulated time for `sitl-emu serve --speed N` and PX4 SITL, wall time for a real vehicle. Vehicle
seconds per wall second over a few wall seconds is the speed it runs at. When that is far from --speed, joyfly's
rates and timeouts (which run --speed times faster than the wall clock) no longer match the vehicle's, so the user
is told once, in one sentence, which --speed to give.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

WINDOW_S = 3.0  # wall seconds of timestamps before judging
TOLERANCE = 1.3  # a vehicle within a factor of 1.3 of --speed is taken to match (a busy machine runs a bit slow)


class SpeedWatch:
    """Feed it every message from the vehicle (`observe`); it calls `warn(sentence)` at most once."""

    def __init__(self, expected: float, warn: Callable[[str], None],
                 wall: Callable[[], float] = time.monotonic) -> None:
        self.expected = expected
        self.warn = warn
        self.wall = wall
        self.measured: float | None = None  # vehicle seconds per wall second, once judged
        self._first: tuple[float, float] | None = None  # (wall s, vehicle s) of the first timestamp

    def observe(self, msg: Any) -> None:
        boot_ms = getattr(msg, "time_boot_ms", None)
        if self.measured is not None or not isinstance(boot_ms, int):
            return
        now_s, vehicle_s = self.wall(), boot_ms / 1000.0
        if self._first is None or vehicle_s < self._first[1]:  # the first timestamp, or the vehicle rebooted
            self._first = (now_s, vehicle_s)
            return
        wall_s = now_s - self._first[0]
        if wall_s < WINDOW_S:
            return
        self.measured = (vehicle_s - self._first[1]) / wall_s
        if not 1 / TOLERANCE <= self.measured / self.expected <= TOLERANCE:
            self.warn(mismatch_sentence(self.measured, self.expected))


def mismatch_sentence(measured: float, expected: float) -> str:
    if measured <= 0:
        return (f"The vehicle's clock has stood still for {WINDOW_S:g} s while joyfly runs at --speed {expected:g}: "
                "is the vehicle paused?")
    about = f"{float(f'{measured:.2g}'):g}"  # two significant digits, never in exponent form
    return (f"The vehicle runs at about {about} times real time but joyfly at --speed {expected:g}: restart "
            f"joyfly with --speed {about} (the vehicle's sitl-emu serve --speed; 1 for PX4 SITL), or its "
            "timeouts and rates will not match the vehicle's.")
