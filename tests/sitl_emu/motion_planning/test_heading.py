"""The auto modes' heading smoothing (sitl_emu/motion_planning/heading.py, after PX4's HeadingSmoothing)."""

from __future__ import annotations

import math

import pytest

from sitl_emu.motion_planning.heading import HeadingSmoother

DT = 0.008
RATE, ACC = math.radians(60.0), math.radians(20.0)  # MPC_YAWRAUTO_MAX, MPC_YAWRAUTO_ACC defaults


def turn(start_deg: float, target_deg: float, seconds: float) -> list[tuple[float, float]]:
    h = HeadingSmoother(math.radians(start_deg))
    h.set_limits(RATE, ACC)
    out = []
    for _ in range(round(seconds / DT)):
        h.update(math.radians(target_deg), DT)
        out.append((h.heading_rad, h.rate_rad_s))
    return out


def test_a_long_turn_accelerates_cruises_at_the_rate_limit_and_brakes_onto_the_target() -> None:
    track = turn(0.0, 170.0, 8.0)
    rates = [r for _, r in track]
    assert max(rates) == pytest.approx(RATE, rel=0.05)
    assert rates[round(1.0 / DT)] == pytest.approx(ACC * 1.0, rel=0.02)  # still ramping up after 1 s
    assert track[-1] == pytest.approx((math.radians(170.0), 0.0), abs=1e-4)


def test_the_turn_takes_the_short_way_across_180_degrees() -> None:
    track = turn(170.0, -170.0, 5.0)
    assert all(r >= 0.0 for _, r in track)  # turning right, through 180
    assert track[-1][0] == pytest.approx(math.radians(-170.0), abs=1e-4)
    assert all(-math.pi <= y < math.pi for y, _ in track)


def test_reset_keeps_the_rate_unless_one_is_given() -> None:
    h = HeadingSmoother(0.0, 0.5)
    h.reset(1.0)
    assert (h.heading_rad, h.rate_rad_s) == (1.0, 0.5)
    h.reset(4.0, 0.0)
    assert (h.heading_rad, h.rate_rad_s) == (pytest.approx(4.0 - 2.0 * math.pi), 0.0)
