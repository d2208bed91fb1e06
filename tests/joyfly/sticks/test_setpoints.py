"""Stick -> local-NED setpoint rules: directions, hold on release, the fence, the altitude band, type masks."""

from __future__ import annotations

import math

import pytest

from joyfly.sticks.setpoints import (
    MASK_POSITION_VELOCITY_YAW,
    MASK_POSITION_YAW,
    Fence,
    Limits,
    Setpoint,
    hold_setpoint,
    initial_setpoint,
    next_setpoint,
)
from joyfly.types import StickCommand

FENCE = Fence((0.0, 0.0, 0.0), 5.0, 0.5, 10.0)
VEL = Limits(control="velocity")
STEP = Limits(control="step")
START = Setpoint((0.0, 0.0, -3.0), 0.0, (0.0, 0.0, 0.0))


def fly(cmd: StickCommand, seconds: float, limits: Limits = VEL, fence: Fence = FENCE,
        start: Setpoint = START) -> Setpoint:
    """Run the setpoint for `seconds` at 20 Hz with a vehicle that tracks it perfectly."""
    sp = start
    for _ in range(round(seconds * 20)):
        sp = next_setpoint(sp, cmd, sp.pos_ned_m, 0.05, limits, fence)
    return sp


@pytest.mark.parametrize("limits", [VEL, STEP])
def test_forward_is_north_right_is_east_up_is_minus_z(limits: Limits) -> None:
    north = fly(StickCommand(forward=0.5), 0.5, limits)
    east = fly(StickCommand(right=0.5), 0.5, limits)
    up = fly(StickCommand(up=1.0), 0.5, limits)
    assert north.pos_ned_m[0] > 0.5 and abs(north.pos_ned_m[1]) < 1e-9
    assert east.pos_ned_m[1] > 0.5 and abs(east.pos_ned_m[0]) < 1e-9
    assert up.pos_ned_m[2] < -3.4


def test_velocity_mode_moves_at_the_commanded_speed_with_feedforward() -> None:
    sp = fly(StickCommand(forward=-0.4), 0.5)  # 2 m/s south, far from the fence
    assert sp.pos_ned_m[0] == pytest.approx(-1.0, abs=0.06)
    assert sp.vel_ned_m_s == pytest.approx((-2.0, 0.0, 0.0))
    assert sp.type_mask == MASK_POSITION_VELOCITY_YAW == 2496


def test_releasing_the_sticks_keeps_the_setpoint() -> None:
    moved = fly(StickCommand(right=-0.5), 0.6)
    held = fly(StickCommand(), 3.0, start=moved)
    assert held.pos_ned_m == pytest.approx(moved.pos_ned_m)
    assert held.vel_ned_m_s == (0.0, 0.0, 0.0)


def test_step_mode_is_vehicle_position_plus_step_times_stick() -> None:
    sp = next_setpoint(START, StickCommand(forward=0.5, right=-0.25), (1.0, 1.0, -3.0), 0.05, STEP, FENCE)
    assert sp.pos_ned_m[:2] == pytest.approx((2.0, 0.5))
    assert sp.type_mask == MASK_POSITION_YAW == 2552
    released = next_setpoint(sp, StickCommand(), (1.5, 0.8, -3.0), 0.05, STEP, FENCE)
    assert released.pos_ned_m == sp.pos_ned_m


def test_velocity_setpoint_stays_on_a_leash_ahead_of_a_slow_vehicle() -> None:
    sp = START
    for _ in range(40):  # vehicle stuck at the origin
        sp = next_setpoint(sp, StickCommand(forward=1.0), (0.0, 0.0, -3.0), 0.05, VEL, FENCE)
    assert math.hypot(sp.pos_ned_m[0], sp.pos_ned_m[1]) <= VEL.leash_m + 1e-9


@pytest.mark.parametrize("limits", [VEL, STEP])
@pytest.mark.parametrize("stick", [StickCommand(forward=1.0), StickCommand(right=-1.0),
                                   StickCommand(forward=-1.0, right=1.0)])
def test_setpoint_never_leaves_the_fence(limits: Limits, stick: StickCommand) -> None:
    sp = fly(stick, 10.0, limits)
    assert FENCE.margin_m(sp.pos_ned_m) >= -1e-9
    assert max(abs(sp.pos_ned_m[0]), abs(sp.pos_ned_m[1])) == pytest.approx(5.0, abs=0.3)


def test_speed_towards_the_fence_is_limited_to_what_can_stop_at_it() -> None:
    near = Setpoint((4.0, 0.0, -3.0), 0.0, (0.0, 0.0, 0.0))
    sp = next_setpoint(near, StickCommand(forward=1.0), near.pos_ned_m, 0.05, VEL, FENCE)
    assert sp.vel_ned_m_s is not None
    assert sp.vel_ned_m_s[0] == pytest.approx(math.sqrt(2 * VEL.brake_acc_m_s2 * 1.0), rel=0.05)
    away = next_setpoint(near, StickCommand(forward=-1.0), near.pos_ned_m, 0.05, VEL, FENCE)
    assert away.vel_ned_m_s is not None and away.vel_ned_m_s[0] == pytest.approx(-5.0)


def test_fence_zero_disables_the_square_but_not_the_altitude_band() -> None:
    open_sky = Fence((0.0, 0.0, 0.0), 0.0, 0.5, 10.0)
    sp = fly(StickCommand(forward=1.0, up=1.0), 20.0, fence=open_sky)
    assert sp.pos_ned_m[0] > 50.0
    assert sp.pos_ned_m[2] == pytest.approx(-10.0)
    assert math.isinf(open_sky.margin_m(sp.pos_ned_m))


def test_altitude_band_is_relative_to_home() -> None:
    fence = Fence((0.0, 0.0, -2.0), 5.0, 1.0, 4.0)  # home 2 m up (local z = -2)
    down = fly(StickCommand(up=-1.0), 10.0, fence=fence, start=Setpoint((0.0, 0.0, -4.0), 0.0, (0.0, 0.0, 0.0)))
    up = fly(StickCommand(up=1.0), 10.0, fence=fence, start=Setpoint((0.0, 0.0, -4.0), 0.0, (0.0, 0.0, 0.0)))
    assert down.pos_ned_m[2] == pytest.approx(-3.0)
    assert up.pos_ned_m[2] == pytest.approx(-6.0)


def test_fence_margin_is_distance_to_the_nearest_side() -> None:
    assert FENCE.margin_m((0.0, 0.0, -3.0)) == pytest.approx(5.0)
    assert FENCE.margin_m((4.0, -1.0, -3.0)) == pytest.approx(1.0)
    assert FENCE.margin_m((0.0, -5.5, -3.0)) == pytest.approx(-0.5)


def test_initial_and_hold_setpoints() -> None:
    sp = initial_setpoint((1.0, 2.0, 0.0), 0.3, FENCE, 3.0)
    assert sp.pos_ned_m == pytest.approx((1.0, 2.0, -3.0))
    assert sp.yaw_rad == pytest.approx(0.3)
    hold = hold_setpoint((9.0, 0.0, -2.0), 0.0, FENCE)
    assert hold.pos_ned_m == pytest.approx((5.0, 0.0, -2.0))


def test_yaw_stick_turns_at_the_max_yaw_rate() -> None:
    sp = fly(StickCommand(yaw=1.0), 1.0)
    assert sp.yaw_rad == pytest.approx(VEL.max_yaw_rate_rad_s, rel=1e-6)
    assert fly(StickCommand(yaw=-1.0), 5.0).yaw_rad == pytest.approx(-math.radians(225) + 2 * math.pi)


def test_braking_starts_earlier_for_a_vehicle_already_moving_fast() -> None:
    sp = Setpoint((2.0, 0.0, -3.0), 0.0, (5.0, 0.0, 0.0))
    still = next_setpoint(sp, StickCommand(forward=1.0), (2.0, 0.0, -3.0), 0.05, VEL, FENCE)
    moving = next_setpoint(sp, StickCommand(forward=1.0), (2.0, 0.0, -3.0), 0.05, VEL, FENCE, (5.0, 0.0, 0.0))
    assert still.vel_ned_m_s is not None and moving.vel_ned_m_s is not None
    assert moving.vel_ned_m_s[0] < still.vel_ned_m_s[0] - 0.5  # predicted at the fence already: no room left


def test_hold_brakes_to_the_point_ahead_of_a_moving_vehicle() -> None:
    hold = hold_setpoint((1.0, 0.0, -3.0), 0.0, FENCE, (2.0, -1.0, 0.0), 0.5)
    assert hold.pos_ned_m == pytest.approx((2.0, -0.5, -3.0))
    assert hold.vel_ned_m_s == (0.0, 0.0, 0.0)
