"""Faults in the vehicle core: INJECT_FAILURE (gps, motor, battery), the battery drain, the data-link loss, the
failure detector; each with PX4's ACK, texts and mode sequence (sources cited in sitl_emu/vehicle/faults.py and
sitl_emu/commander/{failure_injection,battery,fault_failsafes}.py)."""

from __future__ import annotations

import math

import pytest
from support.flights import command, hovering_vehicle

from sitl_emu.console.shell import Shell
from sitl_emu.params import default_registry
from sitl_emu.px4 import MavCmd, MavResult, NavState, Severity
from sitl_emu.types import CommandAck
from sitl_emu.vehicle.vehicle import Vehicle

NAN = math.nan
GPS, BATTERY, MOTOR, RC_SIGNAL = 4.0, 100.0, 101.0, 104.0
OFF, OK = 1.0, 0.0


def _modes(v: Vehicle, seconds: float, *, heartbeat: bool = False) -> list[tuple[float, NavState, bool]]:
    """(time, nav_state, armed) at every change over `seconds`, looked at every 0.1 s."""
    seen: list[tuple[float, NavState, bool]] = []
    for _ in range(round(seconds * 10)):
        if heartbeat:
            v.gcs_heartbeat()
        v.run_for(0.1)
        s = v.snapshot()
        if not seen or seen[-1][1:] != (s.nav_state, s.armed):
            seen.append((v.time_us / 1e6, s.nav_state, s.armed))
    return seen


def _texts(v: Vehicle, after: int = 0) -> list[tuple[Severity, str]]:
    return [(e.severity, e.text) for e in v.events_after(after) if e.statustext]


def test_inject_failure_is_denied_without_sys_failure_en_and_tells_nothing():
    reg = default_registry()
    reg.set("SYS_FAILURE_EN", 0)
    v = Vehicle(params=reg)
    v.run_for(1.0)
    seq = v.last_event_seq
    assert command(v, MavCmd.INJECT_FAILURE, GPS, OFF, 0.0) == CommandAck(MavCmd.INJECT_FAILURE, MavResult.DENIED)
    assert v.events_after(seq) == []
    assert v.faults.failures.entries == {}


def test_set_at_runtime_without_reboot_the_manager_is_not_running_so_no_ack():
    reg = default_registry()
    reg.set("SYS_FAILURE_EN", 0)
    v = Vehicle(params=reg)
    reg.set("SYS_FAILURE_EN", 1)
    assert command(v, MavCmd.INJECT_FAILURE, GPS, OFF, 0.0) is None
    v.reboot()
    assert command(v, MavCmd.INJECT_FAILURE, GPS, OFF, 0.0) == CommandAck(MavCmd.INJECT_FAILURE, MavResult.ACCEPTED)


def test_unsupported_units_and_types_as_px4_main():
    v = Vehicle()
    assert command(v, MavCmd.INJECT_FAILURE, RC_SIGNAL, OFF, 0.0).result == MavResult.UNSUPPORTED  # type: ignore[union-attr]
    assert command(v, MavCmd.INJECT_FAILURE, MOTOR, 2.0, 1.0).result == MavResult.UNSUPPORTED  # type: ignore[union-attr]
    assert _texts(v) == []


def test_gps_off_loses_the_position_after_dead_reckoning_and_descends():
    v = hovering_vehicle()
    seq = v.last_event_seq
    t0 = v.time_us / 1e6
    assert command(v, MavCmd.INJECT_FAILURE, GPS, OFF, 0.0) == CommandAck(MavCmd.INJECT_FAILURE, MavResult.ACCEPTED)
    modes = _modes(v, 15.0)
    assert [(m, a) for _, m, a in modes] == [(NavState.AUTO_LOITER, True), (NavState.DESCEND, True),
                                             (NavState.AUTO_LOITER, False)]
    assert modes[1][0] - t0 == pytest.approx(5.0, abs=0.15)  # EKF2_NOAID_TOUT
    assert _texts(v, seq)[:2] == [(Severity.WARNING, "Injected: gps off, all instances"),
                                  (Severity.CRITICAL, "Failsafe activated")]
    assert not v.snapshot().position_valid
    assert command(v, MavCmd.COMPONENT_ARM_DISARM, 1.0, 0.0).result == MavResult.TEMPORARILY_REJECTED  # type: ignore
    assert command(v, MavCmd.INJECT_FAILURE, GPS, OK, 0.0).result == MavResult.ACCEPTED  # type: ignore[union-attr]
    v.run_for(0.1)
    assert v.snapshot().position_valid and _texts(v)[-1] == (Severity.WARNING, "Cleared: gps, all instances")


def test_motor_off_the_vehicle_falls_and_yaws():
    v = hovering_vehicle()
    assert command(v, MavCmd.INJECT_FAILURE, MOTOR, OFF, 1.0).result == MavResult.ACCEPTED  # type: ignore[union-attr]
    assert _texts(v)[-1] == (Severity.WARNING, "Injected: motor off, instances 1")
    z0 = v.snapshot().pos_ned_m[2]
    v.run_for(0.3)
    s = v.snapshot()
    assert s.motor_commands[0] == 0.0 and s.motors[0] < 0.01  # the allocator stops the output, the rotor spins down
    assert s.vel_ned_m_s[2] > 0.5 and s.pos_ned_m[2] > z0  # falling
    assert abs(s.rates_frd_rad_s[2]) > 0.5 or abs(s.rates_frd_rad_s[0]) > 1.0  # the torque imbalance turns it


def test_motor_off_with_flight_termination_allowed_the_failure_detector_terminates():
    v = hovering_vehicle(CBRK_FLIGHTTERM=0)
    seq = v.last_event_seq
    command(v, MavCmd.INJECT_FAILURE, MOTOR, OFF, 1.0)
    modes = _modes(v, 2.0)
    assert modes[1][1] is NavState.TERMINATION
    assert (Severity.CRITICAL, "Failsafe activated") in _texts(v, seq)


@pytest.mark.slow
def test_battery_drain_low_critical_return_as_com_low_bat_act_3():
    v = hovering_vehicle(SIM_BAT_DRAIN=60.0, SIM_BAT_MIN_PCT=6.0)  # stops at 6 %: critical (7 %), never emergency (5 %)
    seq = v.last_event_seq
    modes = _modes(v, 60.0)
    assert [m for _, m, _ in modes] == [NavState.AUTO_LOITER, NavState.AUTO_RTL]
    texts = _texts(v, seq)
    assert texts[:3] == [(Severity.CRITICAL, "Low battery"), (Severity.CRITICAL, "Critical battery"),
                         (Severity.CRITICAL, "Failsafe activated: entering Hold for 5 seconds")]
    assert (Severity.CRITICAL, "Failsafe activated") in texts[3:]
    crit = next(e for e in v.events_after(seq) if e.text == "Critical battery")
    assert modes[1][0] - crit.time_us / 1e6 == pytest.approx(5.0, abs=0.15)
    assert v.snapshot().battery_remaining == pytest.approx(0.06)
    assert any(e.text == "Low battery level, return advised" and not e.statustext for e in v.events_after(seq))


def test_battery_failure_injected_is_an_emergency_landing():
    v = hovering_vehicle()
    command(v, MavCmd.INJECT_FAILURE, BATTERY, OFF, 0.0)
    modes = _modes(v, 7.0)
    assert [m for _, m, _ in modes] == [NavState.AUTO_LOITER, NavState.AUTO_LAND]
    assert v.snapshot().battery_remaining == 0.0
    assert (Severity.EMERGENCY, "Emergency battery level") in _texts(v)


def test_battery_warning_only_with_com_low_bat_act_0():
    v = hovering_vehicle(COM_LOW_BAT_ACT=0)
    command(v, MavCmd.INJECT_FAILURE, BATTERY, OFF, 0.0)
    assert [m for _, m, _ in _modes(v, 7.0)] == [NavState.AUTO_LOITER]
    assert any(e.text == "Emergency battery level, land immediately" for e in v.events_after(0))


def test_data_link_loss_returns_after_com_dl_loss_t_with_nav_dll_act_2():
    v = hovering_vehicle(NAV_DLL_ACT=2)
    _modes(v, 2.0, heartbeat=True)
    seq, t_last = v.last_event_seq, v.time_us / 1e6
    modes = _modes(v, 20.0)
    lost = next(e for e in v.events_after(seq) if e.text == "Connection to ground station lost")
    assert lost.time_us / 1e6 - t_last == pytest.approx(10.0, abs=0.15)  # COM_DL_LOSS_T
    assert [m for _, m, _ in modes][:2] == [NavState.AUTO_LOITER, NavState.AUTO_RTL]
    assert modes[1][0] - lost.time_us / 1e6 == pytest.approx(5.0, abs=0.15)  # the COM_FAIL_ACT_T Hold
    assert _texts(v, seq)[:2] == [(Severity.INFO, "Connection to ground station lost"),
                                  (Severity.CRITICAL, "Failsafe activated: entering Hold for 5 seconds")]
    v.gcs_heartbeat()
    assert _texts(v)[-1] == (Severity.INFO, "GCS connection regained")


def test_data_link_loss_disabled_by_default_only_tells():
    v = hovering_vehicle()
    _modes(v, 1.0, heartbeat=True)
    assert [m for _, m, _ in _modes(v, 12.0)] == [NavState.AUTO_LOITER]
    assert (Severity.INFO, "Connection to ground station lost") in _texts(v)


def test_failure_shell_command():
    v = Vehicle()
    shell = Shell(v)
    assert shell.execute("failure gps off") == ("WARN  [failure] inject failure unit: gps (4), type: off (1), "
                                                "instance: 0\n")
    assert v.faults.failures.failed(4)
    assert shell.execute("failure motor off -i 2").startswith("WARN  [failure] inject failure unit: motor (101)")
    assert v.faults.failures.mask(101) == 2
    assert "Component 'foo' not found" in shell.execute("failure foo off")
    assert "Failure type 'bar' not found" in shell.execute("failure gps bar")
    assert "ERROR [failure] Result: 3" in shell.execute("failure rc_signal off")
    assert "Not enough arguments." in shell.execute("failure gps")
    v.params.set("SYS_FAILURE_EN", 0)
    assert shell.execute("failure gps ok") == ("ERROR [failure] Failure injection disabled by SYS_FAILURE_EN param.\n"
                                               "Command 'failure' failed, returned 1.\n")


def test_gps_off_in_offboard_position_control_falls_back():
    from sitl_emu.px4 import custom_mode, decode_custom_mode
    from sitl_emu.types import OffboardControlMode, TrajectorySetpoint

    v = hovering_vehicle()
    mode, sp = OffboardControlMode(position=True), TrajectorySetpoint(position_ned_m=(0.0, 0.0, -2.5))
    v.offboard_input(mode, sp)
    main, sub = decode_custom_mode(custom_mode(NavState.OFFBOARD))
    command(v, MavCmd.DO_SET_MODE, 1.0, main, sub)
    command(v, MavCmd.INJECT_FAILURE, GPS, OFF, 0.0)
    seen = []
    for _ in range(80):  # the setpoints keep coming: only the lost position ends OFFBOARD
        v.offboard_input(mode, sp)
        v.run_for(0.1)
        if not seen or seen[-1] != v.snapshot().nav_state:
            seen.append(v.snapshot().nav_state)
    assert seen == [NavState.OFFBOARD, NavState.DESCEND]  # offboardCheck.cpp: "Offboard requires local position"
