"""PX4's health and arming check report, from its source: HealthAndArmingChecks/Common.cpp (Report: which bits a
failing check clears, when a report goes out, the summaries' arguments), checks/modeCheck.cpp (each mode requirement
not met, its event id, level, health component and modes), geofenceCheck.cpp and rcAndDataLinkCheck.cpp."""

from __future__ import annotations

import struct

import pytest

from sitl_emu.commander import arming
from sitl_emu.commander.fault_failsafes import FaultFlags
from sitl_emu.commander.health_report import (
    ALL_MODES,
    BATTERY,
    COMMUNICATION_LINKS,
    REMOTE_CONTROL,
    SYSTEM,
    HealthReporter,
    ReportInputs,
    health_report,
)
from sitl_emu.events import health_events as ev
from sitl_emu.events.library import Log, event_id
from sitl_emu.navigator.geofence import GF_ACTION_RETURN, NO_BREACH, GeofenceResult
from sitl_emu.px4 import NavState

READY = arming.CheckInputs(estimator_ready=True, home_valid=True, offboard_signal=False)
BOOTING = arming.CheckInputs(estimator_ready=False, home_valid=False, offboard_signal=False)


def _inputs(c: arming.CheckInputs = READY, nav: NavState = NavState.AUTO_LOITER, armed: bool = False,
            geofence: GeofenceResult = NO_BREACH, gcs_lost: bool = False, sticks_disabled: bool = False,
            dll_required: bool = False, battery_warning: int = 0) -> ReportInputs:
    faults = FaultFlags(gcs_connection_lost=gcs_lost, battery_warning=battery_warning)
    return ReportInputs.of(nav, armed, c, geofence, faults, sticks_disabled, dll_required)


def _names(report) -> list[str]:
    return [c.event.name for c in report.checks]


def test_booting_every_estimate_is_missing_in_modecheck_order():
    r = health_report(_inputs(BOOTING))
    assert _names(r) == ["check_modes_attitude", "check_modes_local_pos", "check_modes_global_pos",
                         "check_modes_local_alt", "check_modes_mission", "check_modes_offboard_signal",
                         "check_modes_home_position", "check_modes_manual_control"]
    assert [c.level for c in r.checks] == [Log.CRITICAL, Log.ERROR, Log.ERROR, Log.CRITICAL, Log.INFO, Log.ERROR,
                                           Log.INFO, Log.WARNING]
    assert r.arming_error == 1 << SYSTEM and r.arming_warning == 1 << REMOTE_CONTROL
    assert not r.can_arm_in(NavState.AUTO_LOITER) and not r.can_run >> NavState.AUTO_LOITER & 1


def test_ready_in_hold_arming_is_possible_and_only_the_optional_checks_remain():
    r = health_report(_inputs())
    assert _names(r) == ["check_modes_mission", "check_modes_offboard_signal", "check_modes_manual_control"]
    manual = r.checks[-1]
    # no stick input is optional while COM_RC_IN_MODE allows it: reported for all modes (None -> All), a warning
    assert (manual.modes, manual.component, manual.level) == (ALL_MODES, REMOTE_CONTROL, Log.WARNING)
    assert r.can_arm_in(NavState.AUTO_LOITER) and r.can_arm_in(NavState.AUTO_TAKEOFF)
    assert not r.can_arm_in(NavState.AUTO_MISSION) and not r.can_arm_in(NavState.OFFBOARD)
    assert not r.can_arm_in(NavState.POSCTL)  # clearArmingBits(mode_req_manual_control)
    assert r.can_arm_in(NavState.AUTO_RTL)  # mode_req_prevent_arming counts only in the current mode
    assert r.arming_error == 1 << SYSTEM and r.arming_warning == 1 << REMOTE_CONTROL


@pytest.mark.parametrize("nav", [NavState.AUTO_LOITER, NavState.AUTO_TAKEOFF, NavState.AUTO_MISSION,
                                 NavState.AUTO_RTL, NavState.AUTO_LAND, NavState.POSCTL, NavState.ALTCTL,
                                 NavState.STAB, NavState.MANUAL, NavState.OFFBOARD, NavState.ORBIT])
@pytest.mark.parametrize("c", [READY, arming.CheckInputs(True, True, True, manual_control=True, mission_valid=True),
                               arming.CheckInputs(True, False, False, position_lost=True),
                               arming.CheckInputs(True, True, False, mission_required=True)],
                         ids=["bare", "all", "gps", "mission_required"])
def test_can_arm_of_the_current_mode_is_what_the_commander_decides(nav, c):
    assert health_report(_inputs(c, nav)).can_arm_in(nav) == arming.can_arm(nav, c)


def test_a_mode_that_prevents_arming_says_so_only_disarmed():
    disarmed = health_report(_inputs(nav=NavState.AUTO_RTL))
    assert _names(disarmed)[0] == "check_modes_cannot_takeoff" and not disarmed.can_arm_in(NavState.AUTO_RTL)
    assert disarmed.can_run >> NavState.AUTO_RTL & 1  # an arming check only: RTL can still run
    assert "check_modes_cannot_takeoff" not in _names(health_report(_inputs(nav=NavState.AUTO_RTL, armed=True)))


def test_stick_input_disabled_makes_no_manual_control_an_error_of_the_manual_modes():
    manual = health_report(_inputs(sticks_disabled=True)).checks[-1]
    assert manual.level == Log.ERROR and manual.modes == arming.modes_requiring(arming.Req.MANUAL)


def test_a_geofence_breach_fails_arming_in_every_mode_but_lets_them_run():
    r = health_report(_inputs(geofence=GeofenceResult(max_dist=True, custom=True, action=GF_ACTION_RETURN)))
    assert _names(r)[:2] == ["check_gf_violation_max_hor_dist", "check_gf_violation_custom_gf"]
    assert r.can_arm == 0 and r.can_run >> NavState.AUTO_LOITER & 1


def test_com_arm_mis_req_without_a_mission_fails_arming_in_every_mode_but_lets_them_run():
    """modeCheck.cpp: COM_ARM_MIS_REQ makes mission_required_modes NavModes::All for the arming check; the can-run
    bits stay those of mode_req_mission (Mission only)."""
    required = arming.CheckInputs(True, True, False, mission_required=True)
    r = health_report(_inputs(required))
    (mission,) = [c for c in r.checks if c.event is ev.MISSION]
    assert (mission.modes, mission.level, mission.component) == (ALL_MODES, Log.INFO, SYSTEM)
    assert r.can_arm == 0
    assert r.can_run >> NavState.AUTO_LOITER & 1 and not r.can_run >> NavState.AUTO_MISSION & 1
    stored = arming.CheckInputs(True, True, False, mission_valid=True, mission_required=True)
    assert health_report(_inputs(stored)).can_arm_in(NavState.AUTO_LOITER)
    assert arming.arming_failure(NavState.AUTO_LOITER, required) == "No valid mission available"
    assert arming.arming_failure(NavState.AUTO_LOITER, stored) is None


def test_a_lost_ground_station_blocks_arming_only_when_nav_dll_act_needs_it():
    optional = health_report(_inputs(gcs_lost=True))
    (link,) = [c for c in optional.checks if c.event is ev.NO_DATALINK]
    assert (link.level, link.modes, link.component) == (Log.INFO, ALL_MODES, COMMUNICATION_LINKS)
    assert optional.can_arm_in(NavState.AUTO_LOITER) and not optional.present >> COMMUNICATION_LINKS & 1
    assert health_report(_inputs(gcs_lost=True, dll_required=True)).can_arm == 0


def test_a_report_goes_out_on_change_at_most_every_2_s_and_at_once_when_forced():
    reporter = HealthReporter()
    assert reporter.update(1_000_000, _inputs(BOOTING)) == []  # Report::report: not before 2 s
    first = reporter.update(2_000_000, _inputs(BOOTING))
    assert [e.id for e in first] == [event_id(n) for n in ("commander_arming_check_summary", "check_modes_attitude",
                                     "check_modes_local_pos", "check_modes_global_pos", "check_modes_local_alt",
                                     "check_modes_mission", "check_modes_offboard_signal",
                                     "check_modes_home_position", "check_modes_manual_control",
                                     "commander_health_summary")]
    assert reporter.update(2_500_000, _inputs(BOOTING)) == []  # nothing changed
    assert reporter.update(3_000_000, _inputs()) == []  # changed, but within 2 s of the last report
    later = reporter.update(4_000_000, _inputs())  # the change goes out when the window ends
    assert len(later) == 5 and reporter.update(6_500_000, _inputs()) == []
    assert len(reporter.update(6_600_000, _inputs(), force=True)) == 5  # MAV_CMD_RUN_PREARM_CHECKS


def test_the_summaries_and_a_checks_arguments_as_events_send_packs_them():
    summary, *checks, health = HealthReporter().update(2_000_000, _inputs())
    r = health_report(_inputs())
    assert summary.log_levels == 0x88 and health.log_levels == 0x88  # events::Log::Protocol
    assert summary.arguments[:17] == struct.pack("<BIIII", 0, r.arming_error, r.arming_warning, r.can_arm, r.can_run)
    assert health.arguments[:13] == struct.pack("<BIII", 0, r.present, 0, 0)
    mission = checks[0]
    assert mission.log_levels == 0x66 and mission.arguments[:5] == struct.pack(
        "<IB", 1 << NavState.AUTO_MISSION, SYSTEM)  # the modes, the health component index


def test_the_checks_run_at_10_hz_and_at_once_when_the_mode_or_arming_changes():
    reporter = HealthReporter()  # Commander::run: every 100 ms, on _status_changed, or forced
    hold = NavState.AUTO_LOITER
    assert reporter.due(0, hold, False) and not reporter.due(50_000, hold, False)
    assert reporter.due(60_000, hold, True) and not reporter.due(100_000, hold, True)
    assert not reporter.due(110_000, hold, True) and reporter.due(120_000, NavState.AUTO_LAND, True)
    assert reporter.due(220_000, NavState.AUTO_LAND, True) and reporter.due(230_000, hold, True, force=True)


@pytest.mark.parametrize(("warning", "name", "level", "modes"), [
    (1, "check_battery_low", Log.WARNING, ALL_MODES), (2, "check_battery_critical", Log.CRITICAL, ALL_MODES),
    (3, "check_battery_emergency", Log.CRITICAL, ALL_MODES)])
def test_a_battery_warning_is_reported_on_the_battery_component(warning, name, level, modes):
    r = health_report(_inputs(armed=True, battery_warning=warning))
    (battery,) = [c for c in r.checks if c.component == BATTERY]
    assert (battery.event.name, battery.level, battery.modes) == (name, level, modes)
    assert (r.arming_error if level <= Log.ERROR else r.arming_warning) >> BATTERY & 1
    assert r.can_arm == (0 if warning > 1 else r.can_arm) and r.can_run >> NavState.AUTO_LOITER & 1
