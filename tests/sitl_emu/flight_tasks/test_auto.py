"""Navigator tasks as pure functions of NavInput sequences, flown by a simple point-mass follower."""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import pytest

from sitl_emu.control.takeoff import TakeoffState
from sitl_emu.flight_tasks.auto import (
    NavInput,
    SetpointType,
    TakeoffTask,
    Task,
    make_land,
    make_loiter,
    make_reposition,
    make_rtl,
    make_takeoff,
)
from sitl_emu.flight_tasks.rtl import RtlState, rtl_start_text
from sitl_emu.motion_planning.smoothing import AxisSmoother, braking_distance, max_speed_from_distance
from sitl_emu.params import default_registry
from sitl_emu.px4 import Severity
from sitl_emu.types import TrajectorySetpoint, Vec3

DT = 0.02  # PX4's FlightModeManager runs at 50 Hz


@dataclass
class PointMass:
    """Tracks a setpoint like a well-tuned position controller: vel = ff + P * pos error, first-order lag."""

    pos: Vec3 = (0.0, 0.0, 0.0)
    vel: Vec3 = (0.0, 0.0, 0.0)
    yaw: float = 0.0
    t: float = 0.0
    tau_s: float = 0.1
    home: Vec3 = (0.0, 0.0, 0.0)
    armed: bool = True
    takeoff_state: TakeoffState = TakeoffState.FLIGHT
    history: list = field(default_factory=list)

    @property
    def landed(self) -> bool:
        return self.pos[2] >= -0.01 and abs(self.vel[2]) < 0.05

    def nav(self) -> NavInput:
        return NavInput(int(self.t * 1e6), self.pos, self.vel, self.yaw, self.home, 0.0, self.landed, self.armed,
                        self.takeoff_state)

    def follow(self, sp: TrajectorySetpoint) -> None:
        target = []
        for i in range(3):
            p, v = sp.position_ned_m[i], sp.velocity_ned_m_s[i]
            cmd = v if math.isfinite(v) else 0.0
            if math.isfinite(p):
                cmd += (p - self.pos[i]) * (0.95 if i < 2 else 1.0)
            target.append(cmd)
        vel = [self.vel[i] + (target[i] - self.vel[i]) * DT / self.tau_s for i in range(3)]
        pos = [self.pos[i] + vel[i] * DT for i in range(3)]
        if pos[2] > 0.0:  # the ground
            pos[2], vel[2] = 0.0, 0.0
        if math.isfinite(sp.yaw_rad):
            self.yaw = sp.yaw_rad
        self.pos, self.vel = (pos[0], pos[1], pos[2]), (vel[0], vel[1], vel[2])
        self.t += DT

    def fly(self, task: Task, seconds: float) -> list[TrajectorySetpoint]:
        out = []
        for _ in range(round(seconds / DT)):
            sp = task.update(self.nav(), DT)
            out.append(sp)
            self.history.append((self.t, self.pos, self.vel, task.setpoint_type, sp))
            self.follow(sp)
        return out


@pytest.fixture
def params():
    return default_registry()


def hovering(z: float = -2.5, **kw) -> PointMass:
    return PointMass(pos=(0.0, 0.0, z), **kw)


# ---------------------------------------------------------------- smoothing


def test_axis_smoother_reaches_velocity_within_jerk_and_accel_limits():
    axis = AxisSmoother()
    axis.max_jerk, axis.max_accel, axis.max_vel = 4.0, 3.0, 10.0
    prev_a, peak_a, peak_j = 0.0, 0.0, 0.0
    for _ in range(300):
        axis.update_traj(DT)
        axis.update_durations(5.0)
        peak_a = max(peak_a, abs(axis.a))
        peak_j = max(peak_j, abs(axis.a - prev_a) / DT)
        prev_a = axis.a
    assert axis.v == pytest.approx(5.0, abs=1e-3)
    assert axis.a == pytest.approx(0.0, abs=1e-3)
    assert peak_a <= 3.0 + 1e-6
    assert peak_j <= 4.0 + 1e-3


def test_speed_from_distance_lets_the_trajectory_stop_in_that_distance():
    v = max_speed_from_distance(4.0, 3.0, 10.0, 0.0)
    assert braking_distance(v, 4.0, 3.0, 3.0) <= 10.0 + 1e-6
    assert max_speed_from_distance(4.0, 3.0, 0.0, 0.0) == 0.0


# ---------------------------------------------------------------- takeoff


def test_takeoff_default_altitude_message_profile_and_completion(params):
    pm = PointMass()
    task = make_takeoff(pm.nav(), params, None)
    assert task.drain_messages() == [(Severity.INFO, "Using default takeoff altitude: 2.5 m")]
    assert isinstance(task, TakeoffTask)
    finished_at = None
    for _ in range(round(10 / DT)):
        sp = task.update(pm.nav(), DT)
        assert sp.velocity_ned_m_s[2] >= -1.5 - 1e-6  # MPC_TKO_SPEED
        assert sp.acceleration_ned_m_s2[2] >= -0.5 - 1e-6  # MPC_TKO_SPEED / MPC_TKO_RAMP_T
        if task.finished and finished_at is None:
            finished_at = -pm.pos[2]
            assert task.setpoint_type is SetpointType.POSITION
        if not task.finished:
            assert task.setpoint_type is SetpointType.TAKEOFF
        pm.follow(sp)
    assert finished_at == pytest.approx(1.7, abs=0.05)  # MIS_TAKEOFF_ALT - NAV_MC_ALT_RAD
    assert task.target_ned_m == (0.0, 0.0, -2.5)


def test_hold_after_takeoff_keeps_climbing_to_the_full_target(params):
    pm = PointMass()
    task = make_takeoff(pm.nav(), params, None)
    while not task.finished:
        pm.follow(task.update(pm.nav(), DT))
    hold = make_loiter(pm.nav(), params, hold_at_ned_m=task.target_ned_m)
    pm.fly(hold, 12.0)
    assert -pm.pos[2] == pytest.approx(2.5, abs=0.05)
    assert hold.setpoint_type is SetpointType.POSITION


def test_takeoff_explicit_target_below_is_refused_and_finishes_at_once(params):
    pm = hovering(-5.0)
    task = make_takeoff(pm.nav(), params, 3.0)
    assert task.drain_messages() == [(Severity.CRITICAL, "Already higher than takeoff altitude")]
    pm.fly(task, 0.1)
    assert task.finished
    pm.fly(task, 3.0)
    assert pm.pos[2] == pytest.approx(-5.0, abs=0.05)


def test_takeoff_explicit_target_climbs_there(params):
    pm = PointMass()
    task = make_takeoff(pm.nav(), params, 8.0)
    assert task.drain_messages() == []
    pm.fly(task, 25.0)
    assert pm.pos[2] == pytest.approx(-8.0, abs=0.05)


def test_before_the_ramp_the_trajectory_stays_at_the_vehicle_but_wants_takeoff(params):
    pm = PointMass(takeoff_state=TakeoffState.SPOOLUP)
    task = make_takeoff(pm.nav(), params, None)
    task.update(pm.nav(), DT)
    for _ in range(50):
        sp = task.update(pm.nav(), DT)
        assert task.want_takeoff
        assert sp.position_ned_m[2] == pytest.approx(0.0, abs=0.02)
        assert sp.velocity_ned_m_s[2] > 0.6  # PX4 reActivate: the trajectory restarts from 0.7 m/s down
    pm.takeoff_state = TakeoffState.FLIGHT
    pm.fly(task, 8.0)
    assert task.finished


# ---------------------------------------------------------------- hold


@pytest.mark.parametrize("armed", [True, False])
def test_hold_on_the_ground_is_idle(params, armed):
    pm = PointMass(armed=armed)
    task = make_loiter(pm.nav(), params)
    sp = pm.fly(task, 2.0)[-1]
    assert task.setpoint_type is SetpointType.IDLE
    assert not task.want_takeoff
    assert all(math.isnan(c) for c in sp.position_ned_m + sp.velocity_ned_m_s)
    assert sp.acceleration_ned_m_s2[2] > 50.0
    assert pm.pos == (0.0, 0.0, 0.0)


def test_hold_in_flight_stops_at_the_braking_point_and_keeps_altitude(params):
    pm = PointMass(pos=(0.0, 0.0, -10.0), vel=(5.0, 0.0, 0.0))
    task = make_loiter(pm.nav(), params)
    expected_x = braking_distance(5.0, 4.0, 3.0, 0.6 * 4.0)
    assert task.target_ned_m[0] == pytest.approx(expected_x)
    pm.fly(task, 10.0)
    assert pm.pos[0] == pytest.approx(expected_x, abs=0.1)
    assert pm.pos[2] == pytest.approx(-10.0, abs=0.1)
    assert math.hypot(*pm.vel) < 0.05


# ---------------------------------------------------------------- land


def test_land_speed_profile_and_push_down_on_the_ground(params):
    pm = hovering(-20.0)
    task = make_land(pm.nav(), params)
    pm.fly(task, 40.0)
    assert task.setpoint_type is SetpointType.LAND
    speeds = {}
    for _t, pos, vel, _kind, _sp in pm.history:
        height = -pos[2]
        for band, lo, hi in (("fast", 11.0, 18.0), ("mid", 1.5, 4.5), ("crawl", 0.1, 0.5)):
            if lo < height < hi:
                speeds.setdefault(band, []).append(vel[2])
    assert max(speeds["fast"]) == pytest.approx(1.5, abs=0.05)  # MPC_Z_VEL_MAX_DN above MPC_LAND_ALT1
    assert max(speeds["mid"]) == pytest.approx(0.7, abs=0.05)  # MPC_LAND_SPEED below MPC_LAND_ALT2
    assert max(speeds["crawl"]) == pytest.approx(0.3, abs=0.05)  # MPC_LAND_CRWL below MPC_LAND_ALT3
    assert pm.pos[2] == 0.0
    last = pm.history[-1][4]
    assert last.velocity_ned_m_s[2] >= 0.3 - 1e-6  # still commanding a descent on the ground
    # the trajectory keeps running below the ground, but no further than MPC_Z_ERR_MAX (1 m) ahead of the vehicle:
    # PositionSmoothing slows the vertical trajectory's time while the vehicle lags behind it
    assert 0.9 < last.position_ned_m[2] <= 1.0
    assert pm.pos[:2] == pytest.approx((0.0, 0.0), abs=0.01)


def test_land_in_forward_flight_lands_at_the_braking_point(params):
    pm = PointMass(pos=(0.0, 0.0, -3.0), vel=(3.0, 0.0, 0.0))
    task = make_land(pm.nav(), params)
    pm.fly(task, 15.0)
    assert pm.pos[0] == pytest.approx(braking_distance(3.0, 4.0, 3.0, 2.4), abs=0.1)
    assert pm.pos[2] == 0.0


# ---------------------------------------------------------------- return


def rtl_phases(pm: PointMass) -> list[str]:
    return [kind for *_, kind, _sp in pm.history]


def test_rtl_climbs_returns_and_lands_home(params):
    pm = PointMass(pos=(60.0, 30.0, -5.0), yaw=0.0)
    task = make_rtl(pm.nav(), params)
    assert task.drain_messages() == [(Severity.INFO, "RTL: start return at 520 m (31 m above destination)")]
    # 489.4 + 30 m: as 32-bit floats 519.4f - 489.4f = 30.00003, which PX4's ceilf makes 31
    pm.fly(task, 20.0)
    climb = [(pos, vel) for _t, pos, vel, _k, _sp in pm.history if -pos[2] < 29.0]
    assert all(math.hypot(pos[0] - 60.0, pos[1] - 30.0) < 0.5 for pos, _v in climb)  # straight up first
    pm.fly(task, 60.0)
    messages = task.drain_messages()
    assert (Severity.INFO, "RTL: land at destination") in messages
    assert task.setpoint_type is SetpointType.LAND
    assert max(math.hypot(v[0], v[1]) for _t, _p, v, _k, _sp in pm.history) <= 5.0 + 0.1  # MPC_XY_CRUISE
    assert math.hypot(pm.pos[0], pm.pos[1]) < 1.0
    assert pm.pos[2] == 0.0
    heading_home = math.atan2(-30.0, -60.0)
    cruise_yaws = [sp.yaw_rad for t, pos, _v, k, sp in pm.history if k is SetpointType.POSITION and -pos[2] > 29.5
                   and math.hypot(pos[0], pos[1]) > 20.0]
    assert cruise_yaws and all(abs(y - heading_home) < 0.05 for y in cruise_yaws[-10:])
    assert not task.finished


def test_rtl_near_home_uses_the_cone_altitude(params):
    pm = PointMass(pos=(5.0, 0.0, -3.0))
    task = make_rtl(pm.nav(), params)
    assert task.return_alt_up_m == pytest.approx(10.0)  # within NAV_ACC_RAD: twice the distance
    assert task.drain_messages() == [(Severity.INFO, "RTL: start return at 500 m (10 m above destination)")]


@pytest.mark.parametrize(("return_alt", "home_alt", "text"), [
    (518.0000001, 488.0, "518 m (30 m above destination)"),  # 518.0 as a 32-bit float: no rounding up
    (518.0001, 488.0, "519 m (31 m above destination)"),  # a float above 518 rounds up, as ceilf does
    (491.87082, 489.4, "492 m (3 m above destination)"),  # SIH's home altitude, 2.47 m up
    (30.00000001, 0.00000001, "30 m (30 m above destination)"),
])
def test_rtl_start_text_rounds_up_32_bit_floats_as_rtl_direct_cpp(return_alt, home_alt, text):
    assert rtl_start_text(return_alt, home_alt) == f"RTL: start return at {text}"


def test_rtl_above_return_altitude_does_not_climb(params):
    pm = PointMass(pos=(100.0, 0.0, -40.0))
    task = make_rtl(pm.nav(), params)
    assert task.return_alt_up_m == pytest.approx(40.0)
    assert task.state is RtlState.RETURN


def test_rtl_land_delay_descends_waits_then_lands(params):
    params.set("RTL_LAND_DELAY", 2.0)
    pm = PointMass(pos=(40.0, 0.0, -30.0))
    task = make_rtl(pm.nav(), params)
    states = []
    for _ in range(round(60 / DT)):
        states.append((pm.t, task.state, -pm.pos[2]))
        pm.follow(task.update(pm.nav(), DT))
    seen = [s for _t, s, _h in states]
    assert seen.index(RtlState.DESCEND) < seen.index(RtlState.HOLD) < seen.index(RtlState.LAND)
    hold_times = [t for t, s, _h in states if s is RtlState.HOLD]
    assert hold_times[-1] - hold_times[0] == pytest.approx(2.0, abs=0.1)
    assert all(h == pytest.approx(10.0, abs=0.85) for _t, s, h in states if s is RtlState.HOLD)  # RTL_DESCEND_ALT
    assert pm.pos[2] == 0.0


def test_rtl_landed_stays_idle(params):
    pm = PointMass()
    task = make_rtl(pm.nav(), params)
    pm.fly(task, 1.0)
    assert task.setpoint_type is SetpointType.IDLE
    assert pm.pos == (0.0, 0.0, 0.0)


# ---------------------------------------------------------------- reposition


def test_reposition_flies_at_the_given_speed_and_turns_within_the_yaw_rate_and_acceleration_limits(params):
    pm = hovering(-10.0)
    task = make_reposition(pm.nav(), params, (30.0, 0.0, -15.0), math.pi / 2, 2.0)
    pm.fly(task, 30.0)
    assert pm.pos == pytest.approx((30.0, 0.0, -15.0), abs=0.05)
    # PX4's axis time synchronisation (here with the climb) lets the trajectory exceed the speed by a few percent
    assert max(math.hypot(*sp.velocity_ned_m_s[:2]) for *_, sp in pm.history) <= 2.0 * 1.03
    yaws = [sp.yaw_rad for *_, sp in pm.history]
    assert yaws[-1] == pytest.approx(math.pi / 2, abs=1e-3)
    rates = [(b - a) / DT for a, b in itertools.pairwise(yaws)]
    assert max(map(abs, rates)) <= math.radians(60.0) + 1e-6  # MPC_YAWRAUTO_MAX
    assert max(abs(b - a) for a, b in itertools.pairwise(rates)) / DT <= math.radians(20.0) * 1.01  # MPC_YAWRAUTO_ACC
    # HeadingSmoothing: 90 deg at 20 deg/s^2 never reaches 60 deg/s: accelerate half way, brake the other half
    t_turned = next(t for (t, *_), y in zip(pm.history, yaws, strict=True) if abs(y - math.pi / 2) < 1e-3)
    assert t_turned == pytest.approx(2.0 * math.sqrt(90.0 / 20.0), abs=0.1)


def test_reposition_nan_components_keep_the_current_position(params):
    pm = hovering(-10.0)
    task = make_reposition(pm.nav(), params, (math.nan, 20.0, math.nan), math.nan, math.nan)
    assert task.target_ned_m == (0.0, 20.0, -10.0)
    pm.fly(task, 15.0)
    assert pm.pos == pytest.approx((0.0, 20.0, -10.0), abs=0.05)
    assert pm.yaw == pytest.approx(math.pi / 2, abs=0.01)  # MPC_YAW_MODE 0: faces the target


def test_parameter_change_applies_to_a_running_task(params):
    pm = hovering(-2.0)
    task = make_reposition(pm.nav(), params, (40.0, 0.0, -2.0), 0.0, math.nan)
    pm.fly(task, 2.0)
    params.set("MPC_XY_CRUISE", 3.0)
    pm.fly(task, 10.0)
    late = [math.hypot(v[0], v[1]) for t, _p, v, _k, _sp in pm.history if t > 5.0]
    assert max(late) <= 3.05
