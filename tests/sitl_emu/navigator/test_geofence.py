"""The geofence's geometry and rules (navigator/geofence.py), the breach check over time (geofence_monitor.py), the
GF_ACTION failsafe (geofence_failsafe.py) and RTL's rally-point choice (rally.py), without MAVLink."""

from __future__ import annotations

import math

import pytest

from sitl_emu.commander.arming import CheckInputs
from sitl_emu.commander.failsafe import Failsafe, FallbackSettings
from sitl_emu.commander.geofence_failsafe import GeofenceFailsafe
from sitl_emu.events.failsafe_notices import failsafe_notice
from sitl_emu.geo import GeoRef, ned_to_global
from sitl_emu.navigator.geofence import (
    GF_ACTION_HOLD,
    GF_ACTION_LAND,
    GF_ACTION_NONE,
    GF_ACTION_RETURN,
    GF_ACTION_TERMINATE,
    GF_ACTION_WARN,
    TEXT_NO_CURRENT,
    TEXT_NO_HOME,
    GeofenceResult,
    GeofenceSettings,
    GeoPoint,
    build_fence,
    distance_m,
    inside_polygon,
    mission_fence_violation,
    parse_areas,
    point_allowed,
)
from sitl_emu.navigator.geofence_monitor import GeofenceInputs, GeofenceMonitor
from sitl_emu.navigator.mission_store import MissionItem, Plan, plan_id
from sitl_emu.navigator.rally import choose_destination, safe_points
from sitl_emu.px4 import MavCmd, NavState

POLY_IN, POLY_EX = MavCmd.NAV_FENCE_POLYGON_VERTEX_INCLUSION, MavCmd.NAV_FENCE_POLYGON_VERTEX_EXCLUSION
CIRCLE_IN, CIRCLE_EX = MavCmd.NAV_FENCE_CIRCLE_INCLUSION, MavCmd.NAV_FENCE_CIRCLE_EXCLUSION
FENCE_RETURN, RALLY_POINT = MavCmd.NAV_FENCE_RETURN_POINT, MavCmd.NAV_RALLY_POINT

REF = GeoRef(47.397742, 8.545594, 488.0)
HOME = GeoPoint(REF.lat_deg, REF.lon_deg, REF.alt_amsl_m)
S = 1_000_000


def at(north: float, east: float, up: float = 0.0) -> GeoPoint:
    return GeoPoint(*ned_to_global(REF, (north, east, -up)))


def item(command: int, north: float, east: float, p1: float = 0.0, frame: int = 6, z: float = 0.0,
         seq: int = 0) -> MissionItem:
    p = at(north, east)
    return MissionItem(seq, frame, command, 1, p1, 0.0, 0.0, 0.0, round(p.lat_deg * 1e7), round(p.lon_deg * 1e7), z)


def square(command: int, half: float, north: float = 0.0, east: float = 0.0, count: int = 4) -> list[MissionItem]:
    corners = [(-half, -half), (-half, half), (half, half), (half, -half)]
    return [item(command, north + n, east + e, count) for n, e in corners]


def fence_of(items: list[MissionItem], home: GeoPoint | None = HOME):
    fence, texts = build_fence(items, home=home, position=None, landed=True, action=GF_ACTION_HOLD)
    return fence, texts


def passes(fence, north: float, east: float) -> bool:
    p = at(north, east)
    return fence.inside_areas(p.lat_deg, p.lon_deg)


# ---- geometry ---------------------------------------------------------------------------------------------------
def test_inclusion_polygon_contains_its_inside_only():
    fence, texts = fence_of(square(POLY_IN, 50.0))
    assert texts == [] and len(fence.areas) == 1
    assert passes(fence, 0, 0) and passes(fence, 49, -49)
    assert not passes(fence, 51, 0) and not passes(fence, 0, -51) and not passes(fence, 80, 80)


def test_exclusion_polygon_and_circles():
    fence, _ = fence_of([*square(POLY_EX, 10.0, north=40.0), item(CIRCLE_EX, -40, 0, 5.0),
                         item(CIRCLE_IN, 0, 0, 100.0)])
    assert len(fence.areas) == 3
    assert passes(fence, 0, 0)
    assert not passes(fence, 40, 0) and passes(fence, 55, 0)  # inside / beside the exclusion polygon
    assert not passes(fence, -40, 2) and passes(fence, -40, 7)  # inside / beside the exclusion circle
    assert not passes(fence, 0, 101) and passes(fence, 0, 99)  # the inclusion circle's edge


def test_two_inclusion_areas_allow_only_their_intersection():
    """PX4 main ANDs every area: a point must be inside each inclusion area."""
    fence, _ = fence_of(square(POLY_IN, 30.0) + square(POLY_IN, 30.0, north=20.0))
    assert len(fence.areas) == 2
    assert passes(fence, 20, 0)  # in both
    assert not passes(fence, -20, 0) and not passes(fence, 40, 0)  # in one only


def test_empty_fence_and_return_point_pass_everything():
    fence, _ = fence_of([item(FENCE_RETURN, 500, 500)])
    assert fence.empty and passes(fence, 1e4, 1e4)


def test_areas_not_containing_home_are_discarded_with_the_text():
    fence, texts = fence_of([*square(POLY_IN, 10.0, north=100.0), item(CIRCLE_EX, 0, 0, 20.0),
                             item(CIRCLE_IN, 0, 0, 50.0)])
    assert texts == [TEXT_NO_HOME, TEXT_NO_HOME]
    assert len(fence.areas) == 1 and fence.areas[0].command == CIRCLE_IN


def test_in_flight_upload_not_containing_the_vehicle_is_discarded():
    items = [item(CIRCLE_IN, 0, 0, 50.0)]
    flying = dict(home=HOME, position=at(80, 0, 10), landed=False)
    fence, texts = build_fence(items, action=GF_ACTION_HOLD, **flying)
    assert fence.empty and texts == [TEXT_NO_CURRENT]
    fence, texts = build_fence(items, action=GF_ACTION_NONE, **flying)  # no action: no position requirement
    assert len(fence.areas) == 1 and texts == []


def test_vertex_count_larger_than_the_plan_makes_a_polygon_that_contains_nothing():
    """The polygon's last vertices are missing: PX4 fails to load its first vertex pair and answers "outside"."""
    items = square(POLY_IN, 50.0, count=5)
    areas = parse_areas(items)
    assert len(areas) == 1 and not areas[0].loadable
    fence, _texts = fence_of(items, home=None)
    assert not passes(fence, 0, 0)
    assert fence_of(items)[1] == [TEXT_NO_HOME]  # with home known it is discarded


def test_vertex_count_smaller_than_the_run_starts_a_new_polygon():
    """A count of 3 in a run of 4 vertices: the first 3 are a triangle, the 4th starts a broken polygon."""
    items = square(POLY_IN, 50.0, count=3)
    areas = parse_areas(items)
    assert [len(a.vertices) for a in areas] == [3, 1] and not areas[1].loadable


def test_non_global_vertex_ends_the_test_and_nan_radius_contains_nothing():
    tri = square(POLY_IN, 50.0)
    local = [*tri[:2], MissionItem(2, 1, POLY_IN, 1, 4, 0, 0, 0, tri[2].x, tri[2].y, 0.0), *tri[3:]]
    assert not inside_polygon(parse_areas(local)[0], HOME.lat_deg, HOME.lon_deg)
    fence, _texts = fence_of([item(CIRCLE_IN, 0, 0, math.nan)], home=None)
    assert not passes(fence, 0, 0)
    fence, _ = fence_of([item(CIRCLE_EX, 0, 0, math.nan)], home=None)
    assert passes(fence, 0, 0)


def test_zero_vertex_polygon_is_skipped():
    bad = MissionItem(0, 6, POLY_IN, 1, 0.0, 0, 0, 0, 473977420, 85455940, 0.0)
    assert parse_areas([bad]) == []


def test_max_distances_around_home():
    s = GeofenceSettings(max_hor_dist_m=100.0, max_ver_dist_m=50.0)
    fence, _ = fence_of([])
    assert point_allowed(fence, s, at(99, 0, 49), HOME)
    assert not point_allowed(fence, s, at(101, 0, 10), HOME)
    assert not point_allowed(fence, s, at(0, 0, 51), HOME)
    assert point_allowed(fence, s, at(1000, 0, 500), None)  # no home: no limits
    east = at(0, 300)
    assert distance_m(HOME.lat_deg, HOME.lon_deg, east.lat_deg, east.lon_deg) == pytest.approx(300.0, abs=0.01)


# ---- the mission against the fence --------------------------------------------------------------------------------
def test_mission_waypoint_outside_the_fence_is_named_from_one():
    fence, _ = fence_of([item(CIRCLE_IN, 0, 0, 50.0)])
    s = GeofenceSettings()
    mission = [item(22, 0, 0, z=5.0), item(16, 30, 0, z=5.0), item(16, 80, 0, z=5.0)]
    assert mission_fence_violation(mission, fence, s, HOME) == "Geofence violation for waypoint 3"
    assert mission_fence_violation(mission[:2], fence, s, HOME) is None
    rtl = MissionItem(3, 2, 20, 1, 0, 0, 0, 0, 0, 0, 0.0)  # no position: not checked
    assert mission_fence_violation([*mission[:2], rtl], fence, s, HOME) is None


def test_mission_against_max_altitude_uses_relative_altitudes_above_home():
    fence, _ = fence_of([])
    s = GeofenceSettings(max_ver_dist_m=20.0)
    assert mission_fence_violation([item(16, 10, 0, z=15.0)], fence, s, HOME) is None
    assert mission_fence_violation([item(16, 10, 0, z=25.0)], fence, s, HOME) == "Geofence violation for waypoint 1"
    amsl = item(16, 10, 0, frame=5, z=HOME.alt_amsl_m + 25.0)
    assert mission_fence_violation([amsl], fence, s, HOME) == "Geofence violation for waypoint 1"
    assert mission_fence_violation([item(16, 10, 0)], fence, s, None) == "Geofence requires valid home position"


# ---- the breach check over time -----------------------------------------------------------------------------------
def _plan(items: list[MissionItem]) -> Plan:
    return Plan(tuple(items), plan_id(tuple(items)))


def _inputs(north: float, *, armed: bool = True, in_hold: bool = False) -> GeofenceInputs:
    p = at(north, 0, 10)
    return GeofenceInputs(p, p, HOME, landed=False, armed=armed, in_hold=in_hold)


def test_monitor_is_due_without_a_position_only_for_a_new_fence():
    m = GeofenceMonitor()
    plan = _plan([item(CIRCLE_IN, 0, 0, 50.0)])
    assert m.due(0, plan, position_valid=False)  # the fence is still to be built
    m.update(0, plan, GeofenceSettings(action=GF_ACTION_RETURN), GeofenceInputs(None, None, None, True, False, False))
    assert not m.due(8_000, plan, position_valid=False) and m.due(8_000, plan)
    assert m.due(8_000, _plan([]), position_valid=False)


def test_monitor_checks_every_200_ms_and_reports_each_new_breach_once():
    m = GeofenceMonitor()
    plan = _plan([item(CIRCLE_IN, 0, 0, 50.0)])
    s = GeofenceSettings(action=GF_ACTION_RETURN)
    assert m.update(0, plan, s, _inputs(0)).health_texts == [] and not m.result.breached
    step = m.update(100_000, plan, s, _inputs(60))
    assert step.health_texts == [] and not m.result.breached  # not yet 200 ms
    step = m.update(200_004, plan, s, _inputs(60))
    assert m.result.custom and m.result.breached
    assert step.health_texts == ["Geofence: approaching or outside geofence"] and step.reposition is None
    assert m.update(400_008, plan, s, _inputs(60)).health_texts == []
    assert not m.due(500_000, plan) and m.due(600_012, plan) and m.due(500_000, _plan([]))
    m.update(600_012, plan, s, _inputs(0))
    assert not m.result.triggered


def test_monitor_hold_repositions_once_and_latches_while_holding():
    m = GeofenceMonitor()
    plan = _plan([item(CIRCLE_IN, 0, 0, 50.0)])
    s = GeofenceSettings(action=GF_ACTION_HOLD)
    m.update(0, plan, s, _inputs(0))
    step = m.update(300_000, plan, s, _inputs(52))
    assert step.reposition == at(52, 0, 10)
    assert m.update(600_000, plan, s, _inputs(52, in_hold=True)).reposition is None
    m.update(900_000, plan, s, _inputs(40, in_hold=True))
    assert m.result.custom  # inside again while holding after the breach: still breached
    m.update(1_200_000, plan, s, _inputs(40, in_hold=False))
    m.update(1_500_000, plan, s, _inputs(40, in_hold=False))
    assert not m.result.custom


def test_monitor_gf_source_gps_and_action_none():
    m = GeofenceMonitor()
    plan = _plan([item(CIRCLE_IN, 0, 0, 50.0)])
    inside, outside = at(0, 0, 10), at(70, 0, 10)
    m.update(0, plan, GeofenceSettings(source=1), GeofenceInputs(inside, outside, HOME, False, True, False))
    assert m.result.breached
    m2 = GeofenceMonitor()
    m2.update(0, plan, GeofenceSettings(action=GF_ACTION_NONE), GeofenceInputs(outside, outside, HOME, False, True,
                                                                              False))
    assert m2.result.triggered and not m2.result.breached and m2.result.health_texts() == []


def test_health_texts_name_each_limit():
    r = GeofenceResult(max_dist=True, max_alt=True, custom=False, action=GF_ACTION_WARN)
    assert r.health_texts() == ["Geofence: exceeding maximum distance to Home",
                                "Geofence: exceeding maximum altitude above Home"]


# ---- the GF_ACTION failsafe ---------------------------------------------------------------------------------------
BREACH = {a: GeofenceResult(custom=True, action=a) for a in range(6)}
CLEAR = GeofenceResult(action=GF_ACTION_HOLD)


@pytest.mark.parametrize(("action", "mode"), [(GF_ACTION_HOLD, NavState.AUTO_LOITER),
                                              (GF_ACTION_TERMINATE, NavState.TERMINATION),
                                              (GF_ACTION_WARN, None), (GF_ACTION_NONE, None)])
def test_failsafe_immediate_actions(action, mode):
    f = GeofenceFailsafe()
    assert f.update(0, BREACH[action], NavState.POSCTL, 5 * S, False) is mode


@pytest.mark.parametrize(("action", "mode"), [(GF_ACTION_RETURN, NavState.AUTO_RTL),
                                              (GF_ACTION_LAND, NavState.AUTO_LAND)])
def test_failsafe_return_and_land_hold_first_for_com_fail_act_t(action, mode):
    f = GeofenceFailsafe()
    assert f.update(0, BREACH[action], NavState.POSCTL, 5 * S, False) is NavState.AUTO_LOITER
    assert f.hold_s(1 * S) == 4
    assert f.update(5 * S, BREACH[action], NavState.POSCTL, 5 * S, False) is mode
    assert f.update(6 * S, CLEAR, NavState.POSCTL, 5 * S, False) is mode  # kept after the breach clears
    g = GeofenceFailsafe()
    assert g.update(0, BREACH[action], NavState.POSCTL, 0, False) is mode  # COM_FAIL_ACT_T 0: at once
    h = GeofenceFailsafe()
    assert h.update(0, BREACH[action], NavState.POSCTL, 5 * S, True) is mode  # already in a worse failsafe


def test_failsafe_return_while_landing_is_a_warning():
    """framework.cpp getSelectedAction: already landing, a Return (even its Hold first) becomes Action::Warn."""
    f = GeofenceFailsafe()
    assert f.update(0, BREACH[GF_ACTION_RETURN], NavState.AUTO_LAND, 5 * S, False) is None
    assert f.warns
    g = GeofenceFailsafe()
    assert g.update(0, BREACH[GF_ACTION_RETURN], NavState.AUTO_RTL, 5 * S, False) is None
    assert not g.warns


def test_failsafe_warning_lasts_while_breached_and_comes_back_with_a_new_breach():
    """GF_ACTION 1 is Action::Warn with ClearCondition::WhenConditionClears: no mode, gone when back inside."""
    f = GeofenceFailsafe()
    assert f.update(0, BREACH[GF_ACTION_WARN], NavState.POSCTL, 5 * S, False) is None and f.warns
    assert f.update(1 * S, BREACH[GF_ACTION_WARN], NavState.POSCTL, 5 * S, False) is None and f.warns
    assert f.update(2 * S, GeofenceResult(action=GF_ACTION_WARN), NavState.POSCTL, 5 * S, False) is None
    assert not f.warns
    f.update(3 * S, BREACH[GF_ACTION_WARN], NavState.POSCTL, 5 * S, False)
    assert f.warns
    f.update(4 * S, BREACH[GF_ACTION_HOLD], NavState.POSCTL, 5 * S, False)  # GF_ACTION changed during the breach
    assert f.action is NavState.AUTO_LOITER and not f.warns


def test_failsafe_mode_change_takes_over_until_the_breach_clears_and_returns():
    f = GeofenceFailsafe()
    assert f.update(0, BREACH[GF_ACTION_HOLD], NavState.POSCTL, 0, False) is NavState.AUTO_LOITER
    f.reset()  # the user switches mode while still outside
    assert f.update(1 * S, BREACH[GF_ACTION_HOLD], NavState.POSCTL, 0, False) is None
    assert f.update(2 * S, CLEAR, NavState.POSCTL, 0, False) is None
    assert f.update(3 * S, BREACH[GF_ACTION_HOLD], NavState.POSCTL, 0, False) is NavState.AUTO_LOITER


# ---- rally points -------------------------------------------------------------------------------------------------
def rally(north: float, east: float, up: float = 15.0, frame: int = 6) -> MissionItem:
    return item(RALLY_POINT, north, east, frame=frame, z=up)


def test_safe_points_take_global_frames_only():
    pts = safe_points([rally(10, 0), rally(20, 0, frame=5, up=500.0), rally(30, 0, frame=1), item(16, 0, 0)], 488.0)
    assert [(i, round(p.alt_amsl_m, 3)) for i, p in pts] == [(0, 503.0), (1, 500.0)]


def test_rtl_type_0_closest_of_home_and_rally_points():
    points = [rally(200, 0), rally(0, 300)]
    near_rally = choose_destination(0, points, HOME, 0.5, at(180, 0, 20))
    assert near_rally.safe_point_index == 0 and math.isnan(near_rally.yaw_rad)
    assert near_rally.point.alt_amsl_m == pytest.approx(HOME.alt_amsl_m + 15.0)
    home = choose_destination(0, points, HOME, 0.5, at(50, 0, 20))
    assert home.safe_point_index is None and home.point == HOME and home.yaw_rad == 0.5
    close_to_home = choose_destination(0, [rally(5, 0)], HOME, 0.5, at(5, 0, 20))
    assert close_to_home.safe_point_index is None  # within 10 m of home: ignored
    tie = choose_destination(0, [rally(101, 0)], HOME, 0.5, at(50.5, 0, 20))
    assert tie.safe_point_index is None  # not closer by more than 2 m


def test_rtl_type_1_prefers_rally_points_and_type_5_ignores_home():
    points = [rally(200, 0)]
    assert choose_destination(1, points, HOME, 0.0, at(20, 0, 20)).safe_point_index == 0
    assert choose_destination(1, [], HOME, 0.0, at(20, 0, 20)).point == HOME
    assert choose_destination(5, [rally(5, 0)], HOME, 0.0, at(20, 0, 20)).safe_point_index == 0
    here = at(20, 0, 20)
    assert choose_destination(5, [], HOME, 0.0, here).point == here
    assert choose_destination(2, points, HOME, 0.0, at(190, 0, 20)).point == HOME


def test_failsafe_sticks_take_over_only_after_the_delay_of_return_or_land():
    hold = GeofenceFailsafe()
    hold.update(0, BREACH[GF_ACTION_HOLD], NavState.POSCTL, 5 * S, False)
    assert not hold.sticks_may_take_over(10 * S)  # Hold: a mode switch only
    ret = GeofenceFailsafe()
    ret.update(0, BREACH[GF_ACTION_RETURN], NavState.POSCTL, 5 * S, False)
    assert not ret.sticks_may_take_over(1 * S) and ret.sticks_may_take_over(6 * S)
    quick = GeofenceFailsafe()
    quick.update(0, BREACH[GF_ACTION_LAND], NavState.POSCTL, 0, False)
    assert not quick.sticks_may_take_over(1 * S)
    assert GeofenceFailsafe().sticks_may_take_over(0)


def test_failsafe_action_follows_a_gf_action_change_during_the_breach():
    f = GeofenceFailsafe()
    assert f.update(0, BREACH[GF_ACTION_WARN], NavState.OFFBOARD, 5 * S, False) is None
    assert f.update(1 * S, BREACH[GF_ACTION_TERMINATE], NavState.OFFBOARD, 5 * S, False) is NavState.TERMINATION


def test_commander_failsafe_tells_a_new_warning_once_with_no_text_and_no_failsafe():
    """failsafe.py: the geofence's Action::Warn is ranked above no action, keeps the user's mode, is no failsafe, and
    is told (notifyUser: an event, no "Failsafe activated") when it is new; a worse action still wins over it."""
    inputs = CheckInputs(estimator_ready=True, home_valid=True, offboard_signal=False, mission_valid=True)
    settings = FallbackSettings(obl_rc_act=0, rcl_act=2)
    f = Failsafe()

    def decide(now_s: float, result: GeofenceResult):
        return f.update(armed=True, user=NavState.AUTO_MISSION, inputs=inputs, settings=settings,
                        now_us=round(now_s * S), geofence=result, fail_act_us=5 * S)

    first = decide(0.0, BREACH[GF_ACTION_WARN])
    assert (first.nav_state, first.failsafe, first.activated, first.text) == (NavState.AUTO_MISSION, False, True, "")
    assert failsafe_notice(0, first.action, first.delayed_action, first.cause, first.delay_s)[0].name == \
        "commander_failsafe_enter_generic_warn"
    assert not decide(0.1, BREACH[GF_ACTION_WARN]).activated  # told once while it lasts
    assert decide(0.2, GeofenceResult(action=GF_ACTION_WARN)).action == 0  # back inside: gone
    assert decide(0.3, BREACH[GF_ACTION_WARN]).activated  # a new breach: told again
    worse = decide(0.4, BREACH[GF_ACTION_TERMINATE])
    assert (worse.nav_state, worse.failsafe, worse.text) == (NavState.TERMINATION, True, "Failsafe activated")
