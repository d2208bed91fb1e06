"""Return along the mission path (RTL_TYPE 2 and 4), from PX4 main's src/modules/navigator/rtl.cpp
(setRtlTypeAndDestination: which return), rtl_mission_fast_reverse.cpp (the items flown backwards, the landing at
home) and mission_base.cpp (setMissionToClosestItem, set_mission_result, the texts), on a Vehicle (no MAVLink)."""

from __future__ import annotations

import math
from types import SimpleNamespace
from typing import Any

import pytest
from support.mission_flight import MISSION_FRAME, REL, TAKEOFF_ITEM, Flight, do, fly_until_disarmed, wp

from sitl_emu.flight_tasks.rtl_mission import MissionReturn, land_start_index, mission_return
from sitl_emu.geo import GeoRef
from sitl_emu.navigator.mission_items import nav_items
from sitl_emu.navigator.mission_store import PLAN_MISSION, MissionItem, MissionStore
from sitl_emu.navigator.return_path import (
    closest_position_item,
    forward_start_index,
    previous_position_index,
    reverse_start_index,
)
from sitl_emu.px4 import MavCmd, MavResult, NavState

RTL_ITEM = do(MavCmd.NAV_RETURN_TO_LAUNCH)


def _stored(commands: list[int]) -> tuple[MissionItem, ...]:
    return tuple(MissionItem(seq, REL if cmd != MavCmd.DO_LAND_START else MISSION_FRAME, cmd, 1, 0.0, 0.0, 0.0,
                             math.nan, 473977000 + seq * 1000, 85456000, 5.0) for seq, cmd in enumerate(commands))


def _store(commands: list[int], current_seq: int = 0) -> MissionStore:
    store = MissionStore()
    store.replace(PLAN_MISSION, _stored(commands))
    store.current_seq = current_seq
    return store


WP, TKO, LAND, LAND_START = MavCmd.NAV_WAYPOINT, MavCmd.NAV_TAKEOFF, MavCmd.NAV_LAND, MavCmd.DO_LAND_START


def test_rtl_type_picks_the_return_as_rtl_cpp_does() -> None:
    plain = [TKO, WP, WP, WP]
    landing = [TKO, WP, WP, LAND_START, WP, LAND]
    back, on = MissionReturn.REVERSE, MissionReturn.FORWARD
    assert mission_return(2, MissionStore()) is None  # no valid mission: RtlDirect
    assert mission_return(2, _store(plain)) is back and mission_return(4, _store(plain)) is back
    assert mission_return(0, _store(plain)) is None and mission_return(1, _store(plain)) is None
    assert land_start_index(_stored(landing)) == 3 and land_start_index(_stored([TKO, LAND_START, WP])) == -1
    assert mission_return(2, _store(landing)) is on  # a landing pattern: forwards (RtlMissionFast)
    # RTL_TYPE 4: forwards once the landing pattern is nearer than the start (reverseIsFurther)
    assert mission_return(4, _store(landing, current_seq=1)) is back
    assert mission_return(4, _store(landing, current_seq=2)) is on


def _nav(n: float, e: float, alt_m: float) -> Any:
    return SimpleNamespace(pos_ned_m=(n, e, -alt_m))


def test_the_first_item_is_the_one_before_the_mission_s_or_the_closest() -> None:
    items = nav_items(_stored([TKO, WP, MavCmd.DO_CHANGE_SPEED, WP, WP]), GeoRef(47.3977, 8.5456, 488.0), 488.0)
    north = [it.target_ned_m[0] for it in items]
    assert reverse_start_index(items, 4, _nav(0, 0, 5)) == 3  # from AUTO.MISSION: the item before
    assert reverse_start_index(items, 0, _nav(0, 0, 5)) == 0
    assert closest_position_item(items, _nav(north[3] + 0.2, 0.0, 5.0)) == 3  # not the DO item at 2
    assert reverse_start_index(items, -1, _nav(north[1], 0.0, 5.0)) == 1
    assert previous_position_index(items, 3) == 1 and previous_position_index(items, 0) is None
    assert forward_start_index(items, 2, _nav(0, 0, 5)) == 3  # from AUTO.MISSION: the next position item
    assert forward_start_index(items, 5, _nav(0, 0, 5)) == -1  # none left, no land item: nothing to fly


def _fly_to_rtl(rtl_type: int, items: list[tuple]) -> Flight:
    f = Flight(items)
    f.v.params.set("RTL_TYPE", rtl_type)
    f.start()
    f.run_until(lambda: f.v.snapshot().nav_state is NavState.AUTO_RTL, 120.0)
    return f


@pytest.mark.slow
def test_rtl_type_2_flies_the_mission_backwards_at_its_altitudes_and_lands_home() -> None:
    f = _fly_to_rtl(2, [TAKEOFF_ITEM, wp(30, 0), wp(30, 30, 8.0), wp(0, 30), RTL_ITEM])
    rtl_texts = len(f.texts)
    currents, reached, path, _ = fly_until_disarmed(f)
    # from the item before the RTL item back to the takeoff item (MISSION_CURRENT follows), each reported reached;
    # item 3 is where the vehicle already is: reached in the cycle it became current
    assert currents[0] == 4 and currents[-3:] == [2, 1, 0] and reached == [3, 2, 1, 0]
    texts = f.texts[rtl_texts - 1:]
    assert texts[:2] == ["Returning to launch", "Executing Mission"] and "Mission finished, landed" in texts
    assert not any(t.startswith("RTL: start return") for t in texts)  # no direct return
    assert min(math.hypot(p[0] - 30, p[1] - 30) for p in path) < 10.5  # back over item 2 (NAV_ACC_RAD 10 m)
    assert min(math.hypot(p[0] - 30, p[1]) for p in path) < 10.5  # and item 1
    assert max(-p[2] for p in path) < 9.0  # the items' altitudes, not RTL_RETURN_ALT (30 m)
    assert math.hypot(path[-1][0], path[-1][1]) < 1.0
    assert f.store.finished and f.store.current_seq == 0


@pytest.mark.slow
def test_rtl_type_0_still_returns_directly() -> None:
    f = _fly_to_rtl(0, [TAKEOFF_ITEM, wp(30, 0), wp(30, 30, 8.0), wp(0, 30), RTL_ITEM])
    rtl_texts = len(f.texts)
    currents, _, path, _ = fly_until_disarmed(f)
    assert currents == [4] and any(t.startswith("RTL: start return") for t in f.texts[rtl_texts - 1:])
    assert min(math.hypot(p[0] - 30, p[1] - 30) for p in path) > 20.0


@pytest.mark.slow
def test_rtl_type_2_with_a_landing_pattern_flies_on_to_the_mission_s_landing() -> None:
    items = [TAKEOFF_ITEM, wp(30, 0), wp(30, 30), do(MavCmd.DO_LAND_START), wp(0, 30),
             wp(0, 45, 0.0, cmd=MavCmd.NAV_LAND)]
    f = Flight(items)
    f.v.params.set("RTL_TYPE", 2)
    f.start()
    f.run_until(lambda: f.store.current_seq == 2, 120.0)
    f.v.run_for(2.0)
    assert f.command(MavCmd.NAV_RETURN_TO_LAUNCH) == MavResult.ACCEPTED
    rtl_texts = len(f.texts)
    currents, reached, path, _ = fly_until_disarmed(f)
    # on from the item flown, DO_LAND_START skipped, the land item: moved to at the current altitude, landed on
    assert currents == [2, 4, 5] and reached == [2, 4, 5]
    texts = f.texts[rtl_texts:]
    assert "Executing Mission" in texts and "Mission finished, landed" in texts
    assert not any(t.startswith("RTL: start return") for t in texts)
    assert math.hypot(path[-1][0], path[-1][1] - 45.0) < 1.0  # on the mission's landing, not home
