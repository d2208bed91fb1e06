from __future__ import annotations

import math
import random

import pytest
from support import REPO_ROOT
from support.states import hover_state

from flightview.scene import euler_to_q
from sitl_emu.control.attitude import AttitudeControl
from sitl_emu.control.cascade import MulticopterControl
from sitl_emu.control.mixer import allocated_torque, mix
from sitl_emu.control.position import PositionControl, input_valid
from sitl_emu.control.qmath import all_finite3, euler_from_q, isfinite, yaw_from_q
from sitl_emu.control.rate import RateControl
from sitl_emu.control.takeoff import TakeoffState
from sitl_emu.params import default_registry
from sitl_emu.params.settings import cascade_settings
from sitl_emu.physics import RigidBodyState
from sitl_emu.testing.harness import ClosedLoop, hover_loop
from sitl_emu.types import NAN, AttitudeSetpoint, TrajectorySetpoint

HOLD = TrajectorySetpoint(position_ned_m=(0.0, 0.0, -2.5))


@pytest.fixture
def hovering() -> ClosedLoop:
    """A loop settled in hover, built anew for each test: it is deterministic, so this is the same as a copy, and
    the controllers compiled by `make speedups` (mypyc) cannot be deep-copied."""
    return hover_loop(2.5, settle_s=6.0)


def fresh(hovering: ClosedLoop) -> ClosedLoop:
    return hovering


def test_takeoff_then_hover_holds_altitude(hovering):
    loop = fresh(hovering)
    tr = loop.run(10.0, lambda t: HOLD)
    zs = tr.column("pos_ned_m", 2)
    assert max(abs(z + 2.5) for z in zs) < 0.03
    assert loop.control.takeoff_state is TakeoffState.FLIGHT
    assert loop.control.hover_thrust == pytest.approx(0.49, abs=0.01)  # learned from the SIH default airframe


def test_vertical_step_is_tracked_within_the_climb_limit(hovering):
    loop = fresh(hovering)
    sp = TrajectorySetpoint(position_ned_m=(0.0, 0.0, -7.5))
    tr = loop.run(8.0, lambda t: sp)
    vz = tr.column("vel_ned_m_s", 2)
    assert min(vz) > -3.0 - 0.05  # climb <= MPC_Z_VEL_MAX_UP
    assert loop.state.pos_ned_m[2] == pytest.approx(-7.5, abs=0.1)


def test_descent_velocity_is_limited_to_mpc_z_vel_max_dn(hovering):
    loop = fresh(hovering)
    loop.run(8.0, lambda t: TrajectorySetpoint(position_ned_m=(0.0, 0.0, -20.0)))
    sp = TrajectorySetpoint(velocity_ned_m_s=(0.0, 0.0, 4.0))
    tr = loop.run(8.0, lambda t: sp)
    assert max(tr.column("vel_ned_m_s", 2)) < 1.5 + 0.05
    # the drag (SIH_KDV) is taken up by the integrator and the hover-thrust estimate, slowly, as in PX4
    assert tr.column("vel_ned_m_s", 2)[-1] == pytest.approx(1.5, abs=0.05)


def test_velocity_setpoint_is_tracked(hovering):
    loop = fresh(hovering)
    sp = TrajectorySetpoint(velocity_ned_m_s=(2.0, -1.0, 0.0))
    tr = loop.run(15.0, lambda t: sp)
    assert tr.states[500].vel_ned_m_s[0] > 1.3  # most of it within 2 s
    # the drag (SIH_KDV) is taken up by the slow horizontal integrator (MPC_XY_VEL_I_ACC 0.4), as in PX4
    assert loop.state.vel_ned_m_s == pytest.approx((2.0, -1.0, 0.0), abs=0.1)


def test_horizontal_speed_and_tilt_stay_within_the_limits(hovering):
    loop = fresh(hovering)
    sp = TrajectorySetpoint(position_ned_m=(60.0, 80.0, -2.5))
    tr = loop.run(10.0, lambda t: sp)
    speeds = [math.hypot(s.vel_ned_m_s[0], s.vel_ned_m_s[1]) for s in tr.states]
    assert max(speeds) <= 12.0
    assert math.degrees(max(tr.tilt_rad())) < 45.0 + 2.0
    loop.registry.set("MPC_XY_VEL_MAX", 3.0)
    tr = loop.run(6.0, lambda t: TrajectorySetpoint(position_ned_m=(0.0, 0.0, -2.5)))
    speeds = [math.hypot(s.vel_ned_m_s[0], s.vel_ned_m_s[1]) for s in tr.states[-500:]]
    assert max(speeds) <= 3.0 + 0.05  # a parameter change reaches the controller


def test_yaw_setpoint_turns_the_vehicle_90_degrees(hovering):
    loop = fresh(hovering)
    sp = TrajectorySetpoint(position_ned_m=(0.0, 0.0, -2.5), yaw_rad=math.pi / 2)
    loop.run(5.0, lambda t: sp)
    assert math.degrees(yaw_from_q(loop.state.q_wxyz)) == pytest.approx(90.0, abs=1.0)
    assert loop.state.pos_ned_m == pytest.approx((0.0, 0.0, -2.5), abs=0.05)


def test_yawspeed_only_feed_forward_rotates_at_that_rate(hovering):
    loop = fresh(hovering)
    sp = TrajectorySetpoint(position_ned_m=(0.0, 0.0, -2.5), yawspeed_rad_s=0.5)
    tr = loop.run(3.0, lambda t: sp)
    assert tr.states[-1].rates_frd_rad_s[2] == pytest.approx(0.5, abs=0.05)


@pytest.mark.parametrize("bad", [
    TrajectorySetpoint(position_ned_m=(5.0, NAN, -2.5)),  # x without y
    TrajectorySetpoint(position_ned_m=(5.0, 5.0, NAN)),  # no z at all
    TrajectorySetpoint(),  # nothing
])
def test_invalid_setpoint_never_reaches_the_motors_and_stops_the_vehicle(hovering, bad):
    assert not input_valid(bad)
    loop = fresh(hovering)
    loop.run(2.0, lambda t: TrajectorySetpoint(velocity_ned_m_s=(3.0, 0.0, 0.0)))
    tr = loop.run(8.0, lambda t: bad)
    assert all(math.isfinite(m) for ms in tr.motors for m in ms)
    k_hold = round(0.19 / loop.dt_s)
    assert not any(tr.failsafe[:k_hold])  # last valid setpoint kept for 200 ms
    assert all(tr.failsafe[round(0.21 / loop.dt_s):])
    # "stop and wait": from 3 m/s to a standstill (the integrator that held the drag unwinds slowly, as in PX4)
    assert tr.states[500].vel_ned_m_s[0] < 0.5
    assert loop.state.vel_ned_m_s == pytest.approx((0.0, 0.0, 0.0), abs=0.1)
    assert not loop.state.on_ground


def test_takeoff_waits_for_spoolup_then_ramps():
    loop = ClosedLoop()
    tr = loop.run(8.0, lambda t: HOLD)
    idx = {state: tr.takeoff_state.index(state) for state in (TakeoffState.RAMPUP, TakeoffState.FLIGHT)}
    assert tr.takeoff_state[0] is TakeoffState.SPOOLUP
    # COM_SPOOLUP_TIME; a setpoint above the vehicle wants takeoff at once, so ready_for_takeoff is passed through
    assert tr.t_s[idx[TakeoffState.RAMPUP]] == pytest.approx(1.0, abs=0.01)
    assert tr.t_s[idx[TakeoffState.FLIGHT]] == pytest.approx(4.0, abs=0.02)  # + MPC_TKO_RAMP_T
    assert max(max(m) for m in tr.motors[: idx[TakeoffState.RAMPUP]]) < 0.01  # idle before the ramp
    liftoff = next(t for t, s in zip(tr.t_s, tr.states, strict=True) if s.pos_ned_m[2] < -0.05)
    assert 1.5 < liftoff < 4.0
    assert loop.state.pos_ned_m[2] == pytest.approx(-2.5, abs=0.15)


def test_no_takeoff_without_a_climbing_setpoint():
    loop = ClosedLoop()
    tr = loop.run(5.0, lambda t: TrajectorySetpoint(position_ned_m=(0.0, 0.0, 0.0)))
    assert tr.takeoff_state[-1] is TakeoffState.READY_FOR_TAKEOFF
    assert loop.state.on_ground and max(max(m) for m in tr.motors) < 0.01


def test_disarmed_motors_are_off_and_idle_setpoint_gives_zero():
    control = MulticopterControl(cascade_settings(default_registry()))
    state = RigidBodyState()
    assert control.update(state, HOLD, None, False, True, 0, 0.004) == (0.0, 0.0, 0.0, 0.0)
    assert control.takeoff_state is TakeoffState.DISARMED
    assert control.update(state, None, None, True, True, 4000, 0.004) == (0.0, 0.0, 0.0, 0.0)


def test_attitude_setpoint_bypasses_position_control(hovering):
    loop = fresh(hovering)
    q = euler_to_q(math.radians(10.0), 0.0, 0.0)
    att = AttitudeSetpoint(q_wxyz=q, thrust_body=(0.0, 0.0, -0.5))
    loop.run(1.0, lambda t: None, attitude=lambda t: att)
    roll, _, _ = euler_from_q(loop.state.q_wxyz)
    assert math.degrees(roll) == pytest.approx(10.0, abs=1.0)
    assert loop.state.vel_ned_m_s[1] > 0.5  # rolled right -> moving east
    assert loop.control.local_setpoint is None and loop.control.thrust_setpoint == 0.5


def test_body_rate_setpoint_is_followed(hovering):
    loop = fresh(hovering)
    att = AttitudeSetpoint(body_rates_rad_s=(0.0, 0.0, 1.0), thrust_body=(0.0, 0.0, -0.49))
    tr = loop.run(5.0, lambda t: None, attitude=lambda t: att)
    assert tr.states[250].rates_frd_rad_s[2] > 0.8
    # yaw damping (SIH_KDW) is taken up by the yaw-rate integrator (MC_YAWRATE_I 0.1), slowly, as in PX4
    assert loop.state.rates_frd_rad_s[2] == pytest.approx(1.0, abs=0.05)


def test_local_setpoint_reports_the_p_corrected_velocity(hovering):
    loop = fresh(hovering)
    loop.run(0.02, lambda t: TrajectorySetpoint(position_ned_m=(10.0, 0.0, -2.5)))
    local = loop.control.local_setpoint
    assert local.position_ned_m == (10.0, 0.0, -2.5)
    assert local.velocity_ned_m_s[0] == pytest.approx(0.95 * 10.0, abs=0.1)  # MPC_XY_P * error
    assert math.isfinite(local.yaw_rad) and local.yawspeed_rad_s == 0.0


def test_mixer_hover_and_torque_signs_match_the_physics():
    u, _, _ = mix((0.0, 0.0, 0.0), 0.49)
    assert u == pytest.approx((0.49,) * 4)
    for axis in range(3):
        torque = [0.0, 0.0, 0.0]
        torque[axis] = 0.05
        u, pos, neg = mix(tuple(torque), 0.5)
        assert allocated_torque(u) == pytest.approx(tuple(torque))
        assert not any(pos) and not any(neg)


def test_mixer_gives_up_yaw_before_roll_when_saturated():
    u, pos, _ = mix((0.3, 0.0, 0.3), 0.5)
    achieved = allocated_torque(u)
    assert all(0.0 <= m <= 1.0 for m in u)
    assert achieved[0] == pytest.approx(0.3, abs=1e-6)
    assert achieved[2] < 0.3 and pos[2]


def test_attitude_control_commands_rates_towards_the_setpoint_and_limits_them():
    att = AttitudeControl()
    rates = att.update((1.0, 0.0, 0.0, 0.0), euler_to_q(0.1, -0.1, 0.0))
    assert rates[0] == pytest.approx(0.4, rel=0.05) and rates[1] == pytest.approx(-0.4, rel=0.05)
    rates = att.update((1.0, 0.0, 0.0, 0.0), euler_to_q(math.pi / 2, 0.0, 0.0))
    assert rates[0] == pytest.approx(math.radians(220.0))


def test_rate_integrator_is_frozen_while_landed():
    rc = RateControl()
    for _ in range(250):
        rc.update((0.0, 0.0, 0.0), (1.0, 1.0, 1.0), 0.004, landed=True)
    assert rc.integrator == (0.0, 0.0, 0.0)
    for _ in range(2500):
        rc.update((0.0, 0.0, 0.0), (1.0, 1.0, 1.0), 0.004, landed=False)
    assert rc.integrator == pytest.approx((0.3, 0.3, 0.3))  # MC_*_INT_LIM


def test_position_control_handles_acceleration_only_setpoints():
    pc = PositionControl()
    sp = TrajectorySetpoint(acceleration_ned_m_s2=(1.0, 0.0, 0.0), velocity_ned_m_s=(NAN, NAN, 0.0))
    assert input_valid(sp)
    out = pc.update((0.0, 0.0, -5.0), (0.0, 0.0, 0.0), 0.0, sp, 0.004)
    assert out.thrust_ned[0] > 0.0 and out.thrust_ned[2] < 0.0
    assert math.degrees(math.atan2(out.thrust_ned[0], -out.thrust_ned[2])) == pytest.approx(
        math.degrees(math.atan(1.0 / 9.80665)), abs=0.1)


def test_starting_in_the_air_as_flying_holds_position():
    loop = ClosedLoop(state=hover_state(10.0), flying=True)
    sp = TrajectorySetpoint(position_ned_m=(0.0, 0.0, -10.0))
    loop.run(5.0, lambda t: sp)
    assert loop.state.pos_ned_m == pytest.approx((0.0, 0.0, -10.0), abs=0.05)


def test_hover_thrust_estimator_learns_the_true_hover_thrust_and_becomes_valid():
    from sitl_emu.control.hover import HoverThrustEstimator

    hte = HoverThrustEstimator()
    true_hover, g = 0.42, 9.80665
    valid_at = None
    for k in range(1000):  # 10 s at 100 Hz, thrust wandering around hover
        thrust = true_hover * (1.0 + 0.1 * math.sin(k * 0.05))
        acc_up = g * thrust / true_hover - g
        if hte.update(thrust, acc_up, (0.0, 0.0, 0.0), 0.01, k * 10_000) and valid_at is None:
            valid_at = k * 0.01
    assert hte.estimate == pytest.approx(true_hover, abs=0.005)
    assert valid_at is not None and valid_at >= 2.0  # variance small for 2 s first
    assert HoverThrustEstimator().bounds == pytest.approx((0.3, 0.7))  # MPC_THR_HOVER +- HTE_THR_RANGE


def test_horizontal_velocity_limit_keeps_the_position_term_first():
    from sitl_emu.control.control_math import constrain_xy

    vx, vy = constrain_xy((3.0, 0.0), (0.0, 5.0), 4.0)  # P-term 3 m/s north, feed-forward 5 m/s east, limit 4
    assert vx == pytest.approx(3.0) and math.hypot(vx, vy) == pytest.approx(4.0)
    assert constrain_xy((0.0, 0.0), (3.0, 4.0), 0.0) == (0.0, 0.0)  # a zero limit stops, never divides by zero


def test_attitude_setpoint_with_nan_quaternion_never_reaches_the_motors(hovering):
    loop = fresh(hovering)
    att = AttitudeSetpoint(q_wxyz=(NAN, 0.0, 0.0, 0.0), thrust_body=(0.0, 0.0, -0.49))
    tr = loop.run(0.5, lambda t: None, attitude=lambda t: att)
    assert all(math.isfinite(m) for ms in tr.motors for m in ms)


@pytest.mark.parametrize("torque,thrust", [((0.0, 0.0, 0.0), 0.5), ((0.1, -0.05, 0.02), 0.45), ((-0.0, 0.0, -0.0), 0.0),
                                           ((0.0, 0.0, 0.0), 1.0), ((0.3, 0.3, 0.3), 0.95), ((math.nan, 0.1, 0.0), 0.5),
                                           ((0.1, math.inf, 0.0), 0.5), ((0.0, 0.0, 0.0), math.nan)])
def test_mixer_gives_the_plain_mix_exactly_when_nothing_saturates(torque, thrust):
    motors, sat_pos, sat_neg = mix(torque, thrust)
    roll, pitch, yaw = (t if math.isfinite(t) else 0.0 for t in torque)  # NaN and inf count as no demand
    thr = thrust if math.isfinite(thrust) else 0.0
    k = 1.0 / math.sqrt(2.0)  # the mixer's 0.707 roll/pitch scale
    r, p = k * roll, k * pitch
    roll_pitch = (thr - r + p, thr + r - p, thr + r + p, thr - r - p)
    plain = (roll_pitch[0] + yaw, roll_pitch[1] + yaw, roll_pitch[2] - yaw, roll_pitch[3] - yaw)
    if all(0.0 <= m <= 1.0 for m in roll_pitch + plain):
        assert repr(motors) == repr(plain) and sat_pos == sat_neg == (False, False, False)
    else:
        assert all(0.0 <= m <= 1.0 for m in motors)


def test_mixer_unsaturates_roll_and_pitch_before_adding_yaw():
    # ControlAllocationSequentialDesaturation::mixAirmodeDisabled: the roll/pitch/thrust mix puts the front-left
    # motor above 1, so thrust is reduced by the excess first; the yaw added afterwards would have brought that motor
    # back below 1 on its own, but PX4 does not look ahead.
    roll = pitch = 0.03
    thrust, yaw = 0.97, 0.02
    excess = thrust + math.sqrt(2.0) * roll - 1.0  # front-left: T + 0.707 roll + 0.707 pitch
    motors, sat_pos, sat_neg = mix((roll, pitch, yaw), thrust)
    assert sum(motors) / 4.0 == pytest.approx(thrust - excess, abs=1e-9)
    assert allocated_torque(motors) == pytest.approx((roll, pitch, yaw), abs=1e-9)
    assert sat_pos == sat_neg == (False, False, False)  # every torque is delivered, only thrust gave way


def test_attitude_control_gives_finite_limited_rates_for_any_attitude_pair():
    att = AttitudeControl()
    limits = att.settings.rate_max_rad_s
    level = (1.0, 0.0, 0.0, 0.0)
    half_turns = [(0.0, 0.0, 0.0, 1.0), (0.0, 1.0, 0.0, 0.0), (0.0, 0.0, 1.0, 0.0), euler_to_q(math.pi, 0.0, 0.0)]
    rng = random.Random(4)
    pairs = [(level, q) for q in half_turns] + [(q, level) for q in half_turns] + [((-1.0, 0.0, 0.0, 0.0), level)]

    def random_q() -> tuple[float, float, float, float]:
        return euler_to_q(rng.uniform(-1.2, 1.2), rng.uniform(-1.2, 1.2), rng.uniform(-3.1, 3.1))

    pairs += [(random_q(), random_q()) for _ in range(500)]
    for q, q_sp in pairs:
        for ff in (0.0, 0.7, math.nan):
            rates = att.update(q, q_sp, ff)
            assert all(math.isfinite(r) and abs(r) <= lim for r, lim in zip(rates, limits, strict=True)), (q, q_sp)
    assert att.update(level, level) == (0.0, 0.0, 0.0)


def test_a_parameter_set_in_flight_reaches_the_controllers_at_the_next_tick():
    from sitl_emu.vehicle.vehicle import Vehicle

    v = Vehicle()
    v.step()
    v.params.set("MC_ROLL_P", 6.5)
    v.params.set("MPC_XY_VEL_MAX", 4.0)
    v.step()
    control = v.chain.control
    assert control.attitude.settings.gain_p[0] == 6.5
    assert control.position.settings.vel_max_xy == 4.0


def test_controllers_and_physics_never_read_the_parameter_registry():
    # PX4 keeps parameter lookups in the module wrappers; here the vehicle (sitl_emu/params/settings.py) builds the
    # settings.
    import ast

    package = REPO_ROOT / "sitl_emu"
    sources = [*(package / "control").glob("*.py"), package / "physics.py"]
    for path in sources:
        tree = ast.parse(path.read_text())
        imported = {n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)}
        imported |= {a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
        assert not {m for m in imported if m and m.startswith("sitl_emu.params")}, path.name


def test_finiteness_helpers_agree_with_math_isfinite():
    """qmath.isfinite and all_finite3 are arithmetic (for the compiled build): the same answer as math.isfinite for
    signed zeros, the extremes, infinities and NaN, also where a plain sum would overflow (1e308 + 1e308)."""
    values = (0.0, -0.0, 1.5, -1e308, 1e308, 5e-324, math.inf, -math.inf, math.nan)
    for x in values:
        assert isfinite(x) == math.isfinite(x)
    for a in values:
        for b in values:
            for c in values:
                assert all_finite3((a, b, c)) == (math.isfinite(a) and math.isfinite(b) and math.isfinite(c))


def test_at_most_and_at_least_limit_one_side_and_let_nan_through():
    from sitl_emu.control.qmath import at_least, at_most

    assert (at_most(2.0, 1.0), at_most(0.5, 1.0), at_least(-2.0, -1.0), at_least(3.0, -1.0)) == (1.0, 0.5, -1.0, 3.0)
    assert math.isnan(at_most(math.nan, 1.0)) and math.isnan(at_least(math.nan, 1.0))  # PositionControl's NaN path
