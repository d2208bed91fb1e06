"""Vehicle.snapshot(): what telemetry reads must follow the vehicle, however the snapshot is built or cached."""

from __future__ import annotations

import dataclasses
import math

from sitl_emu.geo import GeoRef, ned_to_global
from sitl_emu.px4 import MavState, NavState, custom_mode, decode_custom_mode
from sitl_emu.types import OffboardControlMode, TrajectorySetpoint, VehicleCommand, VehicleSnapshot
from sitl_emu.vehicle.vehicle import Vehicle

NAN = math.nan


def _command(v: Vehicle, command: int, *params: float) -> None:
    v.handle_command(VehicleCommand(command, tuple(params) + (NAN,) * (7 - len(params))))


def _expected_euler(q: tuple[float, float, float, float]) -> tuple[float, float, float]:
    w, x, y, z = q
    roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x))))
    yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return roll, pitch, yaw


def _check(v: Vehicle) -> VehicleSnapshot:
    s = v.snapshot()
    for f in dataclasses.fields(VehicleSnapshot):  # every field is set
        getattr(s, f.name)
    assert (s.lat_deg, s.lon_deg, s.alt_amsl_m) == ned_to_global(v.ref, s.pos_ned_m)
    assert s.euler_rad == _expected_euler(s.q_wxyz)
    assert s.time_us == v.time_us
    assert s.extras == {"system_status": float(v.commander.system_status())}
    assert s.pre_flight_checks_pass == v.commander.pre_flight_checks_pass()
    # the battery simulator (commander/battery.py): full while disarmed, draining while armed
    assert (s.battery_voltage_v, s.battery_remaining) == (v.faults.battery.voltage_v, v.faults.battery.remaining)
    if not s.armed:
        assert s.battery_voltage_v == 16.2 and s.battery_remaining == 1.0
    return s


def test_position_attitude_and_status_follow_the_vehicle_through_a_flight():
    v = Vehicle()
    v.run_for(1.0)
    assert _check(v).extras["system_status"] == MavState.UNINIT  # estimator warming up
    v.run_for(1.5)
    resting = _check(v)
    assert resting.extras["system_status"] == MavState.STANDBY
    _command(v, 400, 1.0)
    _command(v, 22)
    seen_lat = set()
    for _ in range(40):  # takeoff and hold: altitude and attitude change, every snapshot still matches
        v.run_for(0.25)
        s = _check(v)
        seen_lat.add(s.lat_deg)
    assert s.alt_amsl_m > resting.alt_amsl_m + 2.0 and s.armed
    z = s.pos_ned_m[2]
    v.offboard_input(OffboardControlMode(position=True), TrajectorySetpoint(position_ned_m=(10.0, 0.0, z)))
    main_mode, sub = decode_custom_mode(custom_mode(NavState.OFFBOARD))
    _command(v, 176, 1 | 128, main_mode, sub)
    for _ in range(30):
        v.offboard_input(OffboardControlMode(position=True), TrajectorySetpoint(position_ned_m=(10.0, 0.0, z)))
        v.run_for(0.25)
        s = _check(v)
    assert s.nav_state == NavState.OFFBOARD and s.offboard_control is not None
    assert s.lat_deg > resting.lat_deg + 5e-5  # ~10 m north moves the latitude by ~9e-5 degrees
    _command(v, 21)  # land there, then rest on the ground (disarmed) away from the origin
    for _ in range(60):
        v.run_for(0.25)
        s = _check(v)
    assert not s.armed and s.lat_deg > resting.lat_deg + 5e-5 and abs(s.alt_amsl_m - resting.alt_amsl_m) < 0.05


def test_the_snapshot_is_rebuilt_after_a_step_and_after_an_input():
    v = Vehicle()
    v.run_for(2.5)
    first = v.snapshot()
    assert v.snapshot() is first  # cached while nothing happens
    _command(v, 400, 1.0)
    armed = v.snapshot()
    assert armed is not first and armed.armed and not first.armed
    v.step()
    assert v.snapshot().time_us == armed.time_us + v.dt_us


def test_georef_derived_values_do_not_change_its_identity():
    a, b = GeoRef(47.397742, 8.545594, 488.0), GeoRef(47.397742, 8.545594, 488.0)
    assert a == b and hash(a) == hash(b)
    assert repr(a) == "GeoRef(lat_deg=47.397742, lon_deg=8.545594, alt_amsl_m=488.0)"
    assert a.lat_rad == math.radians(47.397742) and a.cos_lat == math.cos(math.radians(47.397742))


def test_controller_outputs_at_rest_are_what_px4_publishes_disarmed():
    """Disarmed, mc_pos_control still runs in position-controlled modes and publishes its idle setpoint (no position or
    velocity, acceleration (0, 0, 100), yaw at the heading); in Manual it does not run (nothing published)."""
    v = Vehicle()
    v.run_for(2.5)
    s = v.snapshot()
    assert s.nav_state == NavState.AUTO_LOITER and not s.armed
    sp = s.local_setpoint
    assert sp is not None and all(math.isnan(c) for c in (*sp.position_ned_m, *sp.velocity_ned_m_s))
    assert sp.acceleration_ned_m_s2 == (0.0, 0.0, 100.0) and sp.yaw_rad == s.euler_rad[2] and sp.yawspeed_rad_s == 0.0
    assert s.attitude_setpoint_q_wxyz == (1.0, 0.0, 0.0, 0.0) and s.thrust_setpoint == 0.0
    assert s.motor_commands == (0.0, 0.0, 0.0, 0.0) and s.offboard_control_last is None
    main_mode, sub = decode_custom_mode(custom_mode(NavState.MANUAL))
    _command(v, 176, 1, main_mode, sub)
    v.run_for(0.1)
    s = v.snapshot()
    assert s.nav_state == NavState.MANUAL and s.local_setpoint is None and s.attitude_setpoint_q_wxyz is None


def test_motor_commands_are_the_mixers_and_the_last_offboard_kinds_stay():
    v = Vehicle()
    v.run_for(2.5)
    v.offboard_input(OffboardControlMode(velocity=True), TrajectorySetpoint(velocity_ned_m_s=(0.0, 0.0, 0.0)))
    _command(v, 400, 1.0)
    _command(v, 22)
    v.run_for(8.0)
    s = v.snapshot()
    assert s.armed and all(0.3 < u < 0.7 for u in s.motor_commands)
    assert s.motor_commands != s.motors  # the state lags the commands (SIH_T_TAU)
    assert s.offboard_control is None and s.offboard_control_last == OffboardControlMode(velocity=True)
