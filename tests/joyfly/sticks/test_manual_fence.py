"""The fence in PX4's manual modes (joyfly/sticks/manual_fence.py): the sticks joyfly sends are limited so the
vehicle stops inside, checked on the rule itself and on a model of PX4's stick dynamics (tests/support/
px4_manual_model.py) flown at joyfly's 25 Hz with telemetry 0.1 s old."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

import pytest
from support.px4_manual_model import Delayed, Plant

from joyfly.sticks.manual import ManualInput
from joyfly.sticks.manual_fence import (
    PX4,
    SetpointEstimate,
    advance_estimate,
    allowed_speed,
    limit_manual,
    limit_tracked,
    px4_shape,
    restart_estimate,
    shaped_world,
    stop_distance,
)
from joyfly.sticks.setpoints import Fence

FENCE = Fence((0.0, 0.0, 0.0), 5.0, 0.5, 10.0)
DT = 0.02  # PX4's flight tasks run at 50 Hz
Sticks = Callable[[float], ManualInput]


def fly(plant: Plant, sticks: Sticks, seconds: float, fence: Fence = FENCE) -> dict[str, float]:
    """Fly the model with joyfly's limiting at 25 Hz on 0.1 s old telemetry; the extremes it reached."""
    seen = Delayed(delay_steps=5)
    sent, est = ManualInput(), SetpointEstimate()
    worst = {"x": -math.inf, "y": -math.inf, "-x": -math.inf, "-y": -math.inf, "alt": -math.inf, "-alt": -math.inf}
    for i in range(round(seconds / DT)):
        pos, vel = seen.push(plant)
        if i % 2 == 0:
            sent, est = limit_tracked(sticks(i * DT), pos, vel, plant.yaw, fence, plant.altitude_mode, est, i * DT)
        plant.step(sent.x / 1000, sent.y / 1000, sent.throttle, DT)
        for key, value in (("x", plant.pos[0]), ("y", plant.pos[1]), ("alt", plant.alt)):
            worst[key] = max(worst[key], value)
            worst["-" + key] = max(worst["-" + key], -value)
    return worst


def held(inp: ManualInput, until_s: float = math.inf) -> Sticks:
    return lambda t: inp if t < until_s else ManualInput()


def test_the_allowance_stops_the_vehicle_at_the_buffer() -> None:
    for room in (0.6, 1.0, 3.0, 10.0, 50.0):
        v = allowed_speed(room)
        assert v > 0 and stop_distance(v) == pytest.approx(room - PX4.buffer_m)
    assert allowed_speed(PX4.buffer_m) == 0.0 and allowed_speed(0.2) == 0.0  # in the buffer: stay
    assert allowed_speed(-0.3) == pytest.approx(-0.3)  # past the side: back in
    assert stop_distance(6.0) > 10.5  # more than real PX4 needs from 6 m/s in POSCTL (reference p_fwd)


WIDE = Fence((0.0, 0.0, 0.0), 50.0, 0.5, 10.0)


def test_sticks_pass_unchanged_far_from_the_fence_or_without_one() -> None:
    inp = ManualInput(x=1000, y=-400, z=800, r=300)
    assert limit_manual(inp, (0.0, 0.0, -3.0), (0.0, 0.0, 0.0), 0.3, WIDE, False) == inp
    open_sky = Fence((0.0, 0.0, 0.0), 0.0, 0.5, 1000.0)
    assert limit_manual(inp, (400.0, 0.0, -3.0), (9.0, 0.0, 0.0), 0.3, open_sky, False) == inp
    released = ManualInput(z=500)  # POSCTL brakes harder by itself
    assert limit_manual(released, (4.9, 0.0, -3.0), (2.0, 0.0, 0.0), 0.0, FENCE, False) == released


def test_near_a_side_the_outward_stick_shrinks_then_brakes_and_the_rest_passes() -> None:
    inp = ManualInput(x=1000, y=1000, z=500, r=700)
    slow = limit_manual(inp, (48.0, 0.0, -3.0), (0.2, 0.0, 0.0), 0.0, WIDE, False)
    assert 0 < slow.x < 1000 and slow.r == 700 and slow.z == 500
    assert px4_shape(slow.y / 1000) == pytest.approx(math.sqrt(0.5), abs=2e-3)  # east as PX4 acted on it: unchanged
    fast = limit_manual(inp, (48.0, 0.0, -3.0), (3.0, 0.0, 0.0), 0.0, WIDE, False)
    assert fast.x < 0  # too fast for the room left: a push inwards
    south = limit_manual(ManualInput(x=-1000), (48.0, 0.0, -3.0), (0.5, 0.0, 0.0), 0.0, WIDE, False)
    assert south.x == -1000  # away from the side: untouched
    ahead = limit_manual(inp, (45.0, 0.0, -3.0), (0.5, 0.0, 0.0), 0.0, WIDE, False, vel_sp_ne=(4.0, 0.0))
    assert ahead.x < limit_manual(inp, (45.0, 0.0, -3.0), (0.5, 0.0, 0.0), 0.0, WIDE, False).x  # PX4's setpoint leads


def test_with_the_nose_east_forward_is_limited_by_the_east_side() -> None:
    inp = ManualInput(x=1000)
    east = limit_manual(inp, (0.0, 48.2, -3.0), (0.0, 1.0, 0.0), math.pi / 2, WIDE, False)
    north = limit_manual(inp, (48.2, 0.0, -3.0), (1.0, 0.0, 0.0), math.pi / 2, WIDE, False)
    assert east.x < 500 and north == inp


LAGS = [0.4, 0.8]  # as PX4 in the reference's braking; twice as slow


@pytest.mark.parametrize("lag_s", LAGS)
@pytest.mark.parametrize("yaw_deg", [0.0, 30.0, 90.0, -135.0])
@pytest.mark.parametrize(("x", "y"), [(1000, 0), (0, 1000), (1000, 1000), (-700, 400)])
def test_posctl_full_stick_stops_inside_the_fence_and_close_to_it(lag_s: float, yaw_deg: float, x: int,
                                                                   y: int) -> None:
    worst = fly(Plant(yaw=math.radians(yaw_deg), lag_s=lag_s), held(ManualInput(x=x, y=y)), 25.0)
    reach = max(worst["x"], worst["y"], worst["-x"], worst["-y"])
    assert 4.0 < reach < 5.0


@pytest.mark.parametrize("lag_s", LAGS)
@pytest.mark.parametrize("release_s", [1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0, 5.0])
def test_posctl_released_any_time_on_the_way_still_stops_inside(lag_s: float, release_s: float) -> None:
    worst = fly(Plant(pos=[-4.0, 0.0], lag_s=lag_s), held(ManualInput(x=1000), until_s=release_s), 20.0)
    assert worst["x"] < 5.0


def test_a_wide_fence_lets_the_vehicle_reach_px4s_full_speed_first() -> None:
    plant = Plant(pos=[-45.0, 0.0])
    worst = fly(plant, held(ManualInput(x=1000)), 40.0, fence=WIDE)
    assert 45.0 < worst["x"] < 50.0 and max(abs(v) for v in plant.vel) < 0.2


@pytest.mark.parametrize(("x", "y", "release_s"), [(1000, 0, 30.0), (1000, 1000, 30.0), (1000, 0, 2.0),
                                                   (0, -1000, 3.0)])
def test_altctl_tilting_at_the_fence_or_drifting_after_it_stays_inside(x: int, y: int, release_s: float) -> None:
    worst = fly(Plant(altitude_mode=True), held(ManualInput(x=x, y=y), until_s=release_s), 30.0)
    assert max(worst["x"], worst["y"], worst["-x"], worst["-y"]) < 5.0


def test_altctl_brakes_a_vehicle_drifting_out_with_no_stick() -> None:
    worst = fly(Plant(altitude_mode=True, vel=[3.0, 0.0], pos=[0.0, 0.0]), held(ManualInput()), 15.0)
    assert worst["x"] < 5.0


def test_the_throttle_climbs_to_below_max_alt_and_descends_to_above_min_alt() -> None:
    up = fly(Plant(alt=1.0), held(ManualInput(z=1000)), 20.0)
    assert 9.0 < up["alt"] < 10.0
    down = fly(Plant(alt=8.0), held(ManualInput(z=0)), 20.0)
    assert 0.5 < -down["-alt"] < 1.5


def test_at_or_past_an_altitude_bound_the_throttle_is_centred() -> None:
    on_ground = limit_manual(ManualInput(z=0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 0.0, FENCE, False)
    assert on_ground.z == 500  # below --min-alt nothing descends (land with LAND or Ctrl-C)
    assert limit_manual(ManualInput(z=1000), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 0.0, FENCE, False).z == 1000
    too_high = limit_manual(ManualInput(z=1000), (0.0, 0.0, -10.2), (0.0, 0.0, 0.0), 0.0, FENCE, False)
    assert too_high.z == 500
    assert limit_manual(ManualInput(z=0), (0.0, 0.0, -10.2), (0.0, 0.0, 0.0), 0.0, FENCE, False).z == 0


def test_the_estimate_of_px4s_velocity_setpoint_leads_the_vehicle_and_follows_px4() -> None:
    plant, est = Plant(), restart_estimate((0.0, 0.0, 0.0), 0.0)
    est = replace(est, stick_ne=shaped_world(ManualInput(x=1000), 0.0))
    for i in range(1, 351):  # 2 s of full stick, then 5 s released
        if i == 101:
            est = replace(est, stick_ne=(0.0, 0.0))
        plant.step(1.0 if i <= 100 else 0.0, 0.0, 0.0, DT)
        est = advance_estimate(est, i * DT, (plant.vel[0], plant.vel[1], 0.0))
        assert est.vel_ne[0] == pytest.approx(plant.v_sp[0], abs=0.05)
        if i == 100:
            assert est.vel_ne[0] > plant.vel[0] + 1.0  # it leads the vehicle
    assert est.vel_ne == (0.0, 0.0) and plant.v_sp == [0.0, 0.0]  # released: PX4 brakes its setpoint to 0


def test_the_estimate_restarts_from_the_measured_velocity_after_a_gap() -> None:
    est = SetpointEstimate((5.0, 0.0), 1.0, (1.0, 0.0), 1.0)
    assert advance_estimate(est, 2.0, (1.5, -0.5, 0.0)) == SetpointEstimate((1.5, -0.5), 1.0, (0.0, 0.0), 2.0)
    assert advance_estimate(SetpointEstimate(), 3.0, (0.2, 0.0, 0.0)).vel_ne == (0.2, 0.0)
    on = advance_estimate(SetpointEstimate((0.0, 0.0), 1.0, (1.0, 0.0), 0.0), 0.4, (0.0, 0.0, 0.0))
    assert on.vel_ne[0] == pytest.approx(0.5 * 8.0 * 0.4 ** 2, rel=0.1)  # the jerk limit: 8 m/s^3 from rest


@pytest.mark.parametrize("noise", [-0.08, -0.04, 0.0, 0.04, 0.08])
def test_at_rest_in_the_buffer_a_held_outward_stick_goes_out_as_a_steady_zero(noise: float) -> None:
    """No jitter from the velocity's noise: PX4 would take a changing stick for a pilot moving it (its takeover of
    an auto mode) and a zero lets it lock the position."""
    for yaw in (0.0, 0.02, -0.02):  # nose north: the push is all eastwards
        out = limit_manual(ManualInput(y=1000), (0.0, 4.6, -3.0), (noise / 2, noise, 0.0), yaw, FENCE, False)
        assert (out.x, out.y) == (0, 0)
