"""The orbit and follow-target flight tasks and the target estimator, alone (no vehicle, no MAVLink).

Sources: FlightTaskOrbit.cpp (applyCommandParameters, _sanitizeParams, the circle setpoints), TargetEstimator.cpp,
FlightTaskAutoFollowTarget.cpp."""

from __future__ import annotations

import math

import pytest

from sitl_emu.flight_tasks.follow import FollowTargetTask
from sitl_emu.flight_tasks.follow_estimator import STALE_US, TargetEstimator, TargetFix
from sitl_emu.flight_tasks.orbit import FailedOrbitHold, OrbitSettings, OrbitTask, apply_orbit, sanitize
from sitl_emu.geo import GeoRef
from sitl_emu.navigator.commands import NavCommand, NavCommandKind
from sitl_emu.navigator.setpoint import NavInput
from sitl_emu.params import default_registry

NAN = math.nan
REF = GeoRef(47.397742, 8.545594, 488.0)


def _nav(pos=(0.0, 0.0, -5.0), vel=(0.0, 0.0, 0.0), yaw=0.0, t_us=10_000_000) -> NavInput:
    return NavInput(t_us, pos, vel, yaw, (0.0, 0.0, 0.0), 0.0, False, True)


def _orbit_cmd(radius=NAN, speed=NAN, yaw=NAN) -> NavCommand:
    return NavCommand(NavCommandKind.ORBIT, NAN, NAN, NAN, speed_m_s=speed, radius_m=radius, yaw_behaviour=yaw)


# ---- orbit --------------------------------------------------------------------------------------------------------
def test_sanitize_clips_radius_speed_and_the_centripetal_limit():
    o = OrbitSettings.from_params(default_registry())
    assert sanitize(0.2, 1.0, o) == (1.0, 1.0)
    assert sanitize(5000.0, 1.0, o) == (1000.0, 1.0)
    assert sanitize(500.0, 30.0, o) == (500.0, 12.0)  # MPC_XY_VEL_MAX
    assert sanitize(50.0, 30.0, o) == (50.0, 10.0)  # sqrt(2 m/s^2 * 50 m)
    r, v = sanitize(8.0, -6.0, o)
    assert r == 8.0 and v == pytest.approx(-4.0)  # v^2 >= 2 r: v = -sqrt(2 r), the direction kept


@pytest.mark.parametrize("radius, speed, ok, want_r, want_v", [
    (10.0, 3.0, True, 10.0, 3.0),
    (-10.0, 3.0, True, 10.0, -3.0),  # negative radius: counter-clockwise
    (10.0, -3.0, True, 10.0, -3.0),  # a negative speed reverses too
    (NAN, NAN, True, 1.0, 1.0),  # the task's start values are kept
    (math.inf, 2.0, True, 1.0, 2.0),  # not finite: kept; 2 m/s is over sqrt(2 * 1 m): 1.41
    (0.5, 2.0, False, 1.0, 1.0),
    (1001.0, 2.0, False, 1.0, 1.0),
])
def test_the_command_sets_radius_and_velocity_as_px4(radius, speed, ok, want_r, want_v):
    task = OrbitTask(_nav(), default_registry())
    assert task.apply(_orbit_cmd(radius, speed), (NAN, NAN, NAN), _nav()) is ok
    expected_v = want_v if abs(want_v) < math.sqrt(2 * want_r) else math.copysign(math.sqrt(2 * want_r), want_v)
    assert (task.radius_m, task.velocity_m_s) == pytest.approx((want_r, expected_v))
    assert bool(task.drain_messages()) is not ok


def test_a_failed_command_leaves_the_failsafe_hold_and_a_new_one_a_new_orbit():
    params, nav = default_registry(), _nav(pos=(3.0, 4.0, -6.0))
    failed = apply_orbit(None, _orbit_cmd(radius=5000.0), nav, params, REF)
    assert isinstance(failed, FailedOrbitHold)
    sp = failed.update(_nav(pos=(9.0, 9.0, -9.0)), 0.02)
    assert sp.position_ned_m == (3.0, 4.0, -6.0) and sp.velocity_ned_m_s == (0.0, 0.0, 0.0)
    assert failed.drain_messages()[0][1] == "Orbit radius limit exceeded"
    again = apply_orbit(failed, _orbit_cmd(radius=10.0), nav, params, REF)
    assert isinstance(again, OrbitTask) and again.radius_m == 10.0


def test_centre_and_altitude_default_to_the_vehicle_and_follow_the_command():
    task = OrbitTask(_nav(pos=(1.0, 2.0, -7.0)), default_registry())
    task.apply(_orbit_cmd(10.0, 2.0), (NAN, NAN, NAN), _nav(pos=(1.0, 2.0, -7.0)))
    assert task.centre_ned_m == (1.0, 2.0, -7.0)
    task.apply(_orbit_cmd(10.0, 2.0), (30.0, NAN, -20.0), _nav())  # lat without lon: both ignored
    assert task.centre_ned_m == (1.0, 2.0, -20.0)


def test_on_the_circle_the_velocity_is_tangential_and_the_nose_faces_the_centre():
    params = default_registry()
    nav = _nav(pos=(10.0, 0.0, -5.0), vel=(0.0, 2.0, 0.0), yaw=math.pi)
    task = OrbitTask(nav, params)
    task.apply(_orbit_cmd(10.0, 2.0), (0.0, 0.0, -5.0), nav)
    for i in range(200):  # 4 s: the tangential speed ramps up at MPC_ACC_HOR
        sp = task.update(_nav(pos=(10.0, 0.0, -5.0), vel=(0.0, 2.0, 0.0), yaw=math.pi, t_us=i * 20_000), 0.02)
    assert math.isnan(sp.position_ned_m[0])
    assert sp.velocity_ned_m_s[:2] == pytest.approx((0.0, 2.0))  # north of the centre, clockwise: east
    assert sp.acceleration_ned_m_s2[:2] == pytest.approx((-0.4, 0.0))  # v^2 / r towards the centre
    assert abs(math.remainder(sp.yaw_rad - math.pi, math.tau)) < 1e-3
    assert sp.yawspeed_rad_s == pytest.approx(0.2)
    status = task.status(REF)
    assert status.radius_m == 10.0 and status.lat_deg == pytest.approx(REF.lat_deg)


@pytest.mark.parametrize("behaviour, yaw_ok", [
    (1, lambda y: y == pytest.approx(0.3)),  # hold the initial heading
    (2, math.isnan),  # uncontrolled
    (3, lambda y: abs(math.remainder(y - math.pi / 2, math.tau)) < 1e-3),  # front tangent: east
])
def test_yaw_behaviours(behaviour, yaw_ok):
    nav = _nav(pos=(10.0, 0.0, -5.0), yaw=0.3)
    task = OrbitTask(nav, default_registry())
    task.apply(_orbit_cmd(10.0, 2.0, behaviour), (0.0, 0.0, -5.0), nav)
    for i in range(400):
        sp = task.update(_nav(pos=(10.0, 0.0, -5.0), yaw=0.3, t_us=i * 20_000), 0.02)
    assert yaw_ok(sp.yaw_rad)
    assert task.status(REF).yaw_behaviour == behaviour


def test_off_the_circle_it_approaches_the_nearest_point():
    nav = _nav(pos=(0.0, 0.0, -5.0))
    task = OrbitTask(nav, default_registry())
    task.apply(_orbit_cmd(10.0, 2.0), (30.0, 0.0, -5.0), nav)
    sp = None
    for i in range(50):
        sp = task.update(_nav(t_us=i * 20_000), 0.02)
    assert sp is not None and sp.velocity_ned_m_s[0] > 0.5 and abs(sp.velocity_ned_m_s[1]) < 1e-6  # north, at it


# ---- target estimator and follow target ---------------------------------------------------------------------------
def test_estimator_first_fix_sets_the_state_then_tracks_a_moving_target():
    est = TargetEstimator(0.1)
    assert est.update(1_000_000, None) is None  # the first cycle publishes nothing
    out = None
    for i in range(1, 300):  # 3 s at 100 Hz, fixes at 10 Hz of a target walking north at 2 m/s
        t = 1_000_000 + i * 10_000
        fix = TargetFix(t, (2.0 * i * 0.01, 0.0, 0.0), (2.0, 0.0, 0.0)) if i % 10 == 0 else None
        out = est.update(t, fix)
    assert out is not None and out.valid and not out.stale
    assert out.pos_ned_m[0] == pytest.approx(2.0 * 2.99, abs=0.5) and out.vel_ned_m_s[0] == pytest.approx(2.0, abs=0.3)


def test_estimator_goes_stale_after_3_s_and_a_nan_altitude_is_no_estimate():
    est = TargetEstimator(0.1)
    est.update(1_000_000, None)
    est.update(1_010_000, TargetFix(1_010_000, (5.0, 5.0, 0.0), (1.0, 0.0, 0.0)))
    out = est.update(1_010_000 + STALE_US + 10_000, None)
    assert out is not None and out.valid and out.stale and out.vel_ned_m_s == (0.0, 0.0, 0.0)
    bad = TargetEstimator(0.1)
    bad.update(1_000_000, None)
    out = bad.update(1_010_000, TargetFix(1_010_000, (5.0, 5.0, NAN), (NAN, NAN, NAN)))
    assert out is not None and not out.valid


def test_follow_task_without_a_target_holds_still():
    task = FollowTargetTask(_nav(), default_registry())
    sp = None
    for i in range(10):
        sp = task.update(_nav(t_us=i * 20_000), 0.02)
    assert sp is not None and all(math.isnan(x) for x in sp.position_ned_m)
    assert sp.velocity_ned_m_s == (0.0, 0.0, 0.0)


def test_follow_task_places_the_vehicle_behind_the_target_at_distance_and_height():
    task = FollowTargetTask(_nav(pos=(0.0, 0.0, -8.0)), default_registry())
    sp = None
    for i in range(1500):  # 30 s, target walking east at 2 m/s
        t = i * 20_000
        target = (20.0, 2.0 * i * 0.02, 0.0)
        task.fix = TargetFix(t, target, (0.0, 2.0, 0.0))
        sp = task.update(_nav(pos=(20.0, target[1] - 8.0, -8.0), t_us=t), 0.02)
    assert sp is not None
    assert sp.position_ned_m[0] == pytest.approx(20.0, abs=0.3)
    assert sp.position_ned_m[1] == pytest.approx(2.0 * 1499 * 0.02 - 8.0, abs=0.5)  # FLW_TGT_FA 180: behind
    assert sp.position_ned_m[2] == pytest.approx(-8.0)  # FLW_TGT_HT above home
    assert sp.yaw_rad == pytest.approx(math.pi / 2, abs=0.05)  # facing the target


@pytest.mark.parametrize("alt_mode, want_z", [(0, -10.0), (2, -3.0 - 10.0)])
def test_follow_parameters_distance_height_angle_and_altitude_mode(alt_mode, want_z):
    params = default_registry()
    for name, value in (("FLW_TGT_DST", 12.0), ("FLW_TGT_HT", 10.0), ("FLW_TGT_FA", 90.0), ("FLW_TGT_ALT_M", alt_mode)):
        params.set(name, value)
    task = FollowTargetTask(_nav(pos=(0.0, 0.0, -10.0)), params)
    sp = None
    for i in range(1500):  # target 3 m up (z -3), walking north at 2 m/s: 90 deg = on its right, i.e. east
        t = i * 20_000
        target = (2.0 * i * 0.02, 0.0, -3.0)
        task.fix = TargetFix(t, target, (2.0, 0.0, 0.0))
        sp = task.update(_nav(pos=(target[0], 12.0, want_z), t_us=t), 0.02)
    assert sp is not None
    assert sp.position_ned_m[0] == pytest.approx(2.0 * 1499 * 0.02, abs=0.5)
    assert sp.position_ned_m[1] == pytest.approx(12.0, abs=0.3)
    assert sp.position_ned_m[2] == pytest.approx(want_z, abs=0.3)
