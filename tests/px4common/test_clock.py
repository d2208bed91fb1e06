"""px4common's clocks: a ScaledClock's seconds are wall seconds times its speed."""

from __future__ import annotations

import time

from px4common.clock import SPEED_MAX, SPEED_MIN, ScaledClock, WallClock


def test_a_scaled_clock_runs_speed_times_faster_from_zero() -> None:
    clock = ScaledClock(50.0)
    wall = WallClock()
    start_wall = wall.now()
    assert 0.0 <= clock.now() < 0.5
    clock.sleep(1.0)  # one scaled second: 20 ms of wall time
    elapsed_wall = wall.now() - start_wall
    assert 0.019 <= elapsed_wall < 0.5
    assert clock.now() >= 1.0 and abs(clock.now() / 50.0 - (wall.now() - start_wall)) < 0.05


def test_sleeping_zero_or_less_returns_at_once() -> None:
    start = time.monotonic()
    ScaledClock(0.1).sleep(-1.0)
    WallClock().sleep(0.0)
    assert time.monotonic() - start < 0.05


def test_the_speed_range_of_both_command_lines() -> None:
    assert (SPEED_MIN, SPEED_MAX) == (0.1, 100.0)
