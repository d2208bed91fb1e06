"""RTL_TYPE 1 and 3 with a mission landing, from PX4 main's src/modules/navigator/rtl.cpp (findRtlDestination: the
mission landing against home and rally points; setRtlTypeAndDestination: RTL_DIRECT_MISSION_LAND),
rtl_direct_mission_land.cpp (the climb, "RTL Mission land: climb to %d m", the landing's items flown as waypoints, the
move to the land item) and mavlink_mission.cpp (the land markers set on upload); on a Vehicle (no MAVLink), in
simulated time."""

from __future__ import annotations

import math

import pytest
from support.mission_flight import MISSION_FRAME, REL, TAKEOFF_ITEM, Flight, do, fly_until_disarmed, wp

from sitl_emu.flight_tasks.rtl_mission import MissionReturn, mission_return
from sitl_emu.navigator.geofence import GeoPoint, distance_m
from sitl_emu.navigator.mission_store import PLAN_MISSION, MissionItem, MissionStore
from sitl_emu.navigator.rally import choose_destination, land_markers, mission_landing
from sitl_emu.px4 import MavCmd, MavResult, NavState

HOME = GeoPoint(47.3977, 8.5456, 489.0)
LAND_START, LAND, WP, RALLY = MavCmd.DO_LAND_START, MavCmd.NAV_LAND, MavCmd.NAV_WAYPOINT, MavCmd.NAV_RALLY_POINT


def _item(seq: int, cmd: int, north_m: float = 0.0, alt_m: float = 0.0) -> MissionItem:
    frame = MISSION_FRAME if cmd == LAND_START else REL
    lat = HOME.lat_deg + north_m / 111_195.0
    return MissionItem(seq, frame, cmd, 1, 0.0, 0.0, 0.0, math.nan, round(lat * 1e7), round(HOME.lon_deg * 1e7), alt_m)


def test_a_land_item_without_a_marker_is_a_landing_for_rtl_type_2() -> None:
    """mavlink_mission.cpp: with no DO_LAND_START the land item is the land start too, so RTL::hasMissionLandStart
    holds and RTL_TYPE 2 flies on to it (RtlMissionFast) rather than back."""
    store = MissionStore()
    store.replace(PLAN_MISSION, tuple(_item(i, c) for i, c in enumerate([MavCmd.NAV_TAKEOFF, WP, WP, LAND])))
    assert mission_return(2, store) is MissionReturn.FORWARD


def _north(north_m: float) -> GeoPoint:
    return GeoPoint(HOME.lat_deg + north_m / 111_195.0, HOME.lon_deg, HOME.alt_amsl_m + 20.0)


def test_the_land_markers_are_set_as_mavlink_mission_cpp_sets_them() -> None:
    cmds = [MavCmd.NAV_TAKEOFF, WP, LAND_START, WP, LAND]
    assert land_markers([_item(i, c) for i, c in enumerate(cmds)]) == (2, 4)
    # no DO_LAND_START: the land item starts the landing; a DO_LAND_START after it does not move the start
    assert land_markers([_item(i, c) for i, c in enumerate([WP, LAND, LAND_START])]) == (1, 1)
    assert land_markers([_item(i, c) for i, c in enumerate([WP, LAND_START, WP])]) == (1, -1)
    items = [_item(0, WP, 0.0, 20.0), _item(1, LAND, 300.0, 2.0)]
    land = mission_landing(items, True, HOME.alt_amsl_m)
    assert land is not None and land.alt_amsl_m == pytest.approx(HOME.alt_amsl_m + 2.0)
    assert distance_m(land.lat_deg, land.lon_deg, HOME.lat_deg, HOME.lon_deg) == pytest.approx(300.0, abs=0.5)
    assert mission_landing(items, False, HOME.alt_amsl_m) is None  # not a valid mission: no mission landing


def test_rtl_type_picks_the_mission_landing_as_find_rtl_destination_does() -> None:
    landing = GeoPoint(HOME.lat_deg + 300.0 / 111_195.0, HOME.lon_deg, HOME.alt_amsl_m)
    near_landing, near_home = _north(280.0), _north(100.0)
    rally_near = [_item(0, RALLY, 250.0, 10.0)]

    def choice(rtl_type: int, here: GeoPoint, rally: list[MissionItem] | None = None) -> tuple[bool, int | None]:
        dest = choose_destination(rtl_type, rally or [], HOME, 0.5, here, landing)
        return dest.mission_land, dest.safe_point_index

    # 0: never the mission landing; 1: the landing (home only without one), wherever the vehicle is
    assert choice(0, near_landing) == (False, None) and choice(1, near_home) == (True, None)
    # 3: the closer of home and the landing
    assert choice(3, near_landing) == (True, None) and choice(3, near_home) == (False, None)
    # the closest wins, the landing against rally points (1), and home too (3); the landing keeps home's yaw
    assert choice(1, near_landing, rally_near) == (True, None) and choice(1, near_home, rally_near) == (False, 0)
    assert choice(3, near_home, rally_near) == (False, None) and choice(3, _north(240.0), rally_near) == (False, 0)
    assert choose_destination(1, [], HOME, 0.5, near_home, landing).yaw_rad == 0.5
    assert choose_destination(1, [], HOME, 0.5, near_home, None).point == HOME  # no landing: home


PATTERN = [TAKEOFF_ITEM, wp(30, 0), wp(30, 30), do(LAND_START), wp(0, 30, 8.0), wp(0, 45, 0.0, cmd=LAND)]


def _rtl_at_item(rtl_type: int, seq: int = 2, after_s: float = 2.0) -> tuple[Flight, int, tuple[float, float, float]]:
    """Return commanded `after_s` after item `seq` became the mission's current item."""
    f = Flight(PATTERN)
    f.v.params.set("RTL_TYPE", rtl_type)
    f.start()
    f.run_until(lambda: f.store.current_seq == seq, 120.0)
    f.v.run_for(after_s)
    assert f.command(MavCmd.NAV_RETURN_TO_LAUNCH) == MavResult.ACCEPTED
    return f, len(f.texts), f.v.snapshot().pos_ned_m


@pytest.mark.slow
def test_rtl_type_1_climbs_then_flies_the_mission_s_landing() -> None:
    f, rtl_texts, at_rtl = _rtl_at_item(1)
    currents, reached, path, modes = fly_until_disarmed(f)
    texts = f.texts[rtl_texts:]
    # RtlDirectMissionLand: MissionBase's "Executing Mission", the climb to the return altitude (RTL_RETURN_ALT 30 m
    # above the land item, as an AMSL altitude rounded up), no direct return
    climb_text = f"RTL Mission land: climb to {math.ceil(f.v.ref.alt_amsl_m + 30.0):d} m"
    assert texts[:3] == ["Returning to launch", "Executing Mission", climb_text], texts
    assert "Mission finished, landed" in texts and not any(t.startswith("RTL: start return") for t in texts)
    # MISSION_CURRENT: the land start during the climb, then the landing's items; the climb is not reported reached
    assert currents == [2, 3, 4, 5] and reached == [3, 4, 5]
    assert modes == [NavState.AUTO_RTL]
    top = max(range(len(path)), key=lambda i: -path[i][2])
    assert -path[top][2] == pytest.approx(30.0, abs=1.5)
    assert math.hypot(path[top][0] - at_rtl[0], path[top][1] - at_rtl[1]) < 5.0  # climbed where it was
    assert min(math.hypot(p[0], p[1] - 30.0) for p in path[top:]) < 10.5  # then over item 4
    assert math.hypot(path[-1][0], path[-1][1] - 45.0) < 1.0  # landed on the mission's land item, not home
    assert f.store.finished and f.store.current_seq == 5


@pytest.mark.slow
def test_rtl_type_3_takes_the_closer_of_home_and_the_mission_s_landing() -> None:
    f, rtl_texts, at = _rtl_at_item(3, seq=4, after_s=1.0)  # near item 2 (30, 30): the land item (0, 45) is closer
    assert math.hypot(at[0], at[1] - 45.0) + 2.0 < math.hypot(at[0], at[1])
    _, _, path, _ = fly_until_disarmed(f)
    assert "Executing Mission" in f.texts[rtl_texts:]
    assert math.hypot(path[-1][0], path[-1][1] - 45.0) < 1.0

    g, rtl_texts, at = _rtl_at_item(3, seq=2)  # past item 1 (30, 0): home is closer
    assert math.hypot(at[0], at[1]) + 2.0 < math.hypot(at[0], at[1] - 45.0)
    _, _, path, _ = fly_until_disarmed(g)
    assert any(t.startswith("RTL: start return") for t in g.texts[rtl_texts:])
    assert math.hypot(path[-1][0], path[-1][1]) < 1.0


@pytest.mark.slow
def test_rtl_type_0_ignores_the_mission_landing() -> None:
    f, rtl_texts, _ = _rtl_at_item(0)
    _, _, path, _ = fly_until_disarmed(f)
    assert any(t.startswith("RTL: start return") for t in f.texts[rtl_texts:])
    assert math.hypot(path[-1][0], path[-1][1]) < 1.0


@pytest.mark.slow
def test_a_qgroundcontrol_landing_pattern_with_a_positioned_marker_is_flown_from_its_approach() -> None:
    """The marker's own position (DO_LAND_START in a global frame) is not flown: the landing starts at the next
    position item, the final approach (LOITER_TO_ALT as a waypoint for a multicopter)."""
    items = [TAKEOFF_ITEM, wp(30, 0), wp(30, 30), wp(60, 60, 12.0, cmd=LAND_START),
             wp(0, 30, 8.0, 1.0, -5.0, 0.0, 1.0, cmd=MavCmd.NAV_LOITER_TO_ALT), wp(0, 45, 0.0, cmd=LAND)]
    f = Flight(items)
    f.v.params.set("RTL_TYPE", 1)
    f.start()
    f.run_until(lambda: f.store.current_seq == 2, 120.0)
    assert f.command(MavCmd.NAV_RETURN_TO_LAUNCH) == MavResult.ACCEPTED
    currents, reached, path, _ = fly_until_disarmed(f)
    assert currents == [2, 3, 4, 5] and reached == [3, 4, 5]
    assert min(math.hypot(p[0] - 60.0, p[1] - 60.0) for p in path) > 20.0
    assert math.hypot(path[-1][0], path[-1][1] - 45.0) < 1.0


@pytest.mark.slow
def test_a_landing_at_home_keeps_the_return_altitude_computed_on_the_ground() -> None:
    """rtl.cpp initRtlMissionType: the return altitude is handed to the mission landing when the return type becomes
    it, here on the ground at home before the flight, next to the land item: 2 x the distance to it
    (computeReturnAltitude), so Return does not climb."""
    items = [TAKEOFF_ITEM, wp(30, 0), wp(30, 30), do(LAND_START), wp(0, 10, 8.0), wp(0, 0, 0.0, cmd=LAND)]
    f = Flight(items)
    f.v.params.set("RTL_TYPE", 1)
    f.start()
    f.run_until(lambda: f.store.current_seq == 2, 120.0)
    f.v.run_for(2.0)
    assert f.command(MavCmd.NAV_RETURN_TO_LAUNCH) == MavResult.ACCEPTED
    texts = len(f.texts)
    currents, _, path, _ = fly_until_disarmed(f)
    assert "Executing Mission" in f.texts[texts:]
    assert not any(t.startswith("RTL Mission land: climb") for t in f.texts[texts:])
    assert max(-p[2] for p in path) < 15.0  # the items' altitudes (5-8 m), no climb towards RTL_RETURN_ALT (30 m)
    assert currents[-2:] == [4, 5] and math.hypot(path[-1][0], path[-1][1]) < 1.0
