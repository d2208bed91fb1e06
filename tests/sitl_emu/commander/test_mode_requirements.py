"""Each mode's requirements as PX4 main's src/modules/commander/ModeUtil/mode_requirements.cpp sets them, the
estimate the emulator has (HealthAndArmingChecks/checks/estimatorCheck.cpp setModeRequirementFlags), and what
follows from them as PX4 decides it: which modes can run and arm (modeCheck.cpp), the mode fallback when the GPS is
lost (failsafe/failsafe.cpp checkModeFallback: Position -> Altitude), the refused switch's text (Commander.cpp
printRejectMode) and the health report's can_arm / can_run bits (HealthAndArmingChecks/Common.cpp)."""

from __future__ import annotations

import pytest
from support.flights import command, hovering_vehicle

from sitl_emu.commander import arming
from sitl_emu.commander.arming import CheckInputs, Req
from sitl_emu.commander.fault_failsafes import FaultFlags
from sitl_emu.commander.health_report import ReportInputs, health_report
from sitl_emu.navigator.geofence import NO_BREACH
from sitl_emu.px4 import MavCmd, MavResult, NavState, Severity, custom_mode, decode_custom_mode
from sitl_emu.types import ManualControlSetpoint
from sitl_emu.vehicle.vehicle import Vehicle

GPS, OFF = 4.0, 1.0
# what the emulator's estimator can be in: warming up, ready, ready with the GPS lost past EKF2_NOAID_TOUT
WARMING_UP = dict(estimator_ready=False, position_lost=False)
READY = dict(estimator_ready=True, position_lost=False)
GPS_LOST = dict(estimator_ready=True, position_lost=True)
MC_MODES = (NavState.MANUAL, NavState.ALTCTL, NavState.POSCTL, NavState.AUTO_MISSION, NavState.AUTO_LOITER,
            NavState.AUTO_RTL, NavState.POSITION_SLOW, NavState.GUIDED_COURSE, NavState.ALTITUDE_CRUISE,
            NavState.ACRO, NavState.DESCEND, NavState.TERMINATION, NavState.OFFBOARD, NavState.STAB,
            NavState.AUTO_TAKEOFF, NavState.AUTO_LAND, NavState.AUTO_FOLLOW_TARGET, NavState.AUTO_PRECLAND,
            NavState.ORBIT, NavState.AUTO_VTOL_TAKEOFF)


def _inputs(estimate: dict[str, bool], *, sticks: bool = True, offboard: bool = True) -> CheckInputs:
    """Everything but the estimate present (home, mission, offboard signal, sticks), so the estimate decides."""
    return CheckInputs(home_valid=True, offboard_signal=offboard, manual_control=sticks, mission_valid=True,
                       **estimate)


# mode_requirements.cpp, per nav_state: (needs an attitude, an altitude, a local position (strict or relaxed), a
# global position) -- read off getModeRequirements' multicopter branch
ESTIMATE_NEEDS = {
    NavState.MANUAL: (False, False, False, False),
    NavState.ACRO: (False, False, False, False),
    NavState.STAB: (True, False, False, False),
    NavState.ALTCTL: (True, True, False, False),
    NavState.ALTITUDE_CRUISE: (True, True, False, False),
    NavState.POSCTL: (True, True, True, False),
    NavState.POSITION_SLOW: (True, True, True, False),
    NavState.GUIDED_COURSE: (True, True, True, False),
    NavState.AUTO_LAND: (True, True, True, False),
    NavState.AUTO_TAKEOFF: (True, True, True, False),
    NavState.AUTO_LOITER: (True, True, True, True),
    NavState.AUTO_MISSION: (True, True, True, True),
    NavState.AUTO_RTL: (True, True, True, True),
    NavState.DESCEND: (True, False, False, False),
    NavState.OFFBOARD: (True, False, False, False),
    NavState.ORBIT: (True, True, True, False),
}


@pytest.mark.parametrize("nav", list(ESTIMATE_NEEDS), ids=[n.name for n in ESTIMATE_NEEDS])
def test_which_estimate_each_mode_needs(nav):
    attitude, altitude, local, global_ = ESTIMATE_NEEDS[nav]
    r = arming.requirements(nav)
    assert bool(r & Req.ATTITUDE) is attitude and bool(r & Req.LOCAL_ALT) is altitude
    assert bool(r & (Req.LOCAL_POSITION | Req.LOCAL_POSITION_RELAXED)) is local
    assert bool(r & Req.GLOBAL_POSITION) is global_


def test_the_relaxed_position_is_for_the_modes_where_the_pilot_corrects_the_drift():
    relaxed = {n for n in MC_MODES if arming.requirements(n) & Req.LOCAL_POSITION_RELAXED}
    strict = {n for n in MC_MODES if arming.requirements(n) & Req.LOCAL_POSITION}
    assert relaxed == {NavState.POSCTL, NavState.POSITION_SLOW, NavState.GUIDED_COURSE, NavState.AUTO_LAND}
    assert strict == {NavState.AUTO_MISSION, NavState.AUTO_LOITER, NavState.AUTO_RTL, NavState.AUTO_TAKEOFF,
                      NavState.AUTO_FOLLOW_TARGET, NavState.AUTO_PRECLAND, NavState.ORBIT, NavState.AUTO_VTOL_TAKEOFF}


def test_with_the_gps_lost_the_altitude_modes_still_run_and_the_position_modes_do_not():
    c = _inputs(GPS_LOST)
    runs = {n for n in MC_MODES if arming.can_run(n, c)}
    assert runs == {NavState.MANUAL, NavState.ACRO, NavState.STAB, NavState.ALTCTL, NavState.ALTITUDE_CRUISE,
                    NavState.DESCEND, NavState.TERMINATION, NavState.OFFBOARD}
    assert arming.arming_failure(NavState.POSCTL, c) == "No valid local position estimate"
    assert arming.arming_failure(NavState.AUTO_LOITER, c) == "No valid local position estimate"
    assert arming.can_arm(NavState.ALTCTL, c)


def test_warming_up_only_the_modes_without_an_attitude_estimate_can_arm():
    c = _inputs(WARMING_UP)
    assert {n for n in MC_MODES if arming.can_arm(n, c)} == {NavState.MANUAL, NavState.ACRO}
    assert arming.arming_failure(NavState.STAB, c) == "No valid attitude estimate"
    assert arming.arming_failure(NavState.AUTO_RTL, c) == "Mode not suitable for arming"
    assert not arming.can_arm(NavState.MANUAL, _inputs(WARMING_UP, sticks=False))


def test_offboard_position_setpoints_need_the_local_position():
    from sitl_emu.types import OffboardControlMode as Ocm
    lost = arming.estimate_valid(estimator_ready=True, position_lost=True)
    assert not arming.offboard_available(Ocm(position=True), lost)
    assert not arming.offboard_available(Ocm(velocity=True), lost)
    assert arming.offboard_available(Ocm(attitude=True), lost)
    assert arming.offboard_available(Ocm(acceleration=True), lost)
    assert not arming.offboard_available(Ocm(acceleration=True), arming.estimate_valid(False, False))


# ---- the health report says what the commander does ----------------------------------------------------------
def _report(c: CheckInputs, nav: NavState = NavState.AUTO_LOITER, armed: bool = False):
    return health_report(ReportInputs.of(nav, armed, c, NO_BREACH, FaultFlags(), False, False))


@pytest.mark.parametrize("estimate", [WARMING_UP, READY, GPS_LOST], ids=["warming up", "ready", "gps lost"])
@pytest.mark.parametrize("sticks", [True, False], ids=["sticks", "no sticks"])
def test_the_reports_can_arm_and_can_run_bits_are_the_commanders_for_every_mode(estimate, sticks):
    c = _inputs(estimate, sticks=sticks, offboard=False)
    for nav in MC_MODES:
        r = _report(c, nav)
        assert r.can_arm_in(nav) == arming.can_arm(nav, c), nav.name
        assert bool(r.can_run >> int(nav) & 1) == arming.can_run(nav, c), nav.name


def test_with_the_gps_lost_the_report_names_the_position_checks_and_their_modes():
    r = _report(_inputs(GPS_LOST, sticks=True))
    checks = {c.event.name: c.modes for c in r.checks}
    assert "check_modes_local_alt" not in checks and "check_modes_attitude" not in checks
    assert checks["check_modes_local_pos"] == arming.modes_requiring(Req.LOCAL_POSITION | Req.LOCAL_POSITION_RELAXED)
    assert checks["check_modes_global_pos"] == sum(1 << n for n in (NavState.AUTO_MISSION, NavState.AUTO_LOITER,
                                                                     NavState.AUTO_RTL))
    assert not checks["check_modes_local_pos"] >> NavState.ALTCTL & 1
    assert r.can_arm_in(NavState.ALTCTL) and r.can_arm_in(NavState.STAB) and not r.can_arm_in(NavState.POSCTL)


def test_warming_up_the_altitude_check_names_the_modes_that_need_an_altitude():
    checks = {c.event.name: c.modes for c in _report(_inputs(WARMING_UP)).checks}
    assert checks["check_modes_local_alt"] == arming.modes_requiring(Req.LOCAL_ALT)
    assert checks["check_modes_local_alt"] >> NavState.ALTCTL & 1
    assert not checks["check_modes_attitude"] >> NavState.MANUAL & 1 and not checks["check_modes_attitude"] >> \
        NavState.ACRO & 1


# ---- in flight: GPS lost with a joystick ---------------------------------------------------------------------
def _fly_with_sticks(v: Vehicle, seconds: float) -> list[NavState]:
    """Centred sticks at 10 Hz; the nav_state at every change."""
    seen: list[NavState] = []
    for _ in range(round(seconds * 10)):
        v.manual_control_input(ManualControlSetpoint(throttle=0.0))
        v.run_for(0.1)
        if not seen or seen[-1] is not v.snapshot().nav_state:
            seen.append(v.snapshot().nav_state)
    return seen


def _set_mode(v: Vehicle, nav: NavState):
    main, sub = decode_custom_mode(custom_mode(nav))
    return command(v, MavCmd.DO_SET_MODE, 1.0, main, sub)


def test_gps_lost_in_position_mode_falls_back_to_altitude_and_position_is_refused():
    v = hovering_vehicle()
    _fly_with_sticks(v, 0.5)
    assert _set_mode(v, NavState.POSCTL).result == MavResult.ACCEPTED  # type: ignore[union-attr]
    _fly_with_sticks(v, 1.0)
    command(v, MavCmd.INJECT_FAILURE, GPS, OFF, 0.0)
    # checkModeFallback: Position cannot run -> Altitude, which needs only an altitude estimate (the barometer's)
    assert _fly_with_sticks(v, 6.0) == [NavState.POSCTL, NavState.ALTCTL]
    assert v.snapshot().armed and v.commander.failsafe
    seq = v.last_event_seq
    assert _set_mode(v, NavState.ALTCTL).result == MavResult.ACCEPTED  # type: ignore[union-attr]
    assert v.snapshot().nav_state is NavState.ALTCTL and not v.commander.failsafe
    assert _set_mode(v, NavState.POSCTL).result == MavResult.TEMPORARILY_REJECTED  # type: ignore[union-attr]
    texts = [(e.severity, e.text) for e in v.events_after(seq) if e.statustext]
    assert texts == [(Severity.CRITICAL, "Switching to Position is currently not available")]
    assert _fly_with_sticks(v, 1.0) == [NavState.ALTCTL]


def test_check_inputs_are_shared_while_equal_and_made_again_when_a_value_changes() -> None:
    cache = arming.CheckInputsCache()
    values = dict(estimator_ready=True, home_valid=True, offboard_signal=False, manual_control=False,
                  mission_valid=True, position_lost=False, mission_required=False)
    first = cache.of(**values)
    assert cache.of(**values) is first  # the commander's next cycle, nothing changed: the same read-only inputs
    assert (first.estimator_ready, first.home_valid, first.mission_valid) == (True, True, True)
    lost = cache.of(**{**values, "position_lost": True})
    assert lost is not first and lost.position_lost and not first.position_lost
    assert cache.of(**values) is not lost and cache.of(**values).available() == first.available()
