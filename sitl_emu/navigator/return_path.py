"""Return along the mission path (RTL_TYPE 2 and 4): the mission's position items flown as plain waypoints, backwards
to the start then home, or forwards to its landing; and the mission's landing flown from its start (RTL_TYPE 1 and 3,
MissionLandNavigator: rtl_direct_mission_land.cpp). Pure: no MAVLink, simulated time comes with the NavInput.

Written from PX4 main's src/modules/navigator/rtl_mission_fast_reverse.cpp and rtl_mission_fast.cpp (on_activation,
setNextMissionItem, setActiveMissionItems, handleLanding) on top of mission_base.cpp (goToPreviousPositionItem,
goToNextPositionItem, setMissionToClosestItem, set_mission_result, handleLanding), for a multicopter that is not a
VTOL:
- the first item: from AUTO.MISSION, backwards the item before the one the mission was flying, forwards the first
  position item from it on (none left: the land item); from another mode, the position item closest to the vehicle
  (3D distance);
- each position item is flown as a waypoint (LOITER_TO_ALT kept), no hold time, continuing; the triplet's next is
  the following position item the way the return goes; DO_* items in between are skipped; no climb is inserted;
- backwards, at the takeoff item (or the first position item): a climb work item to its position and altitude (not
  reported as reached), then the landing at home: a move there at the current altitude if farther than
  NAV_ACC_RAD, then land;
- forwards, the mission's land item: a move to it at the current altitude if farther than NAV_ACC_RAD, then land;
- once landed: "Mission finished, landed" and idle. MISSION_CURRENT shows the item flown (set_mission_result), and the
  mission's current item stays where the return left it (setMissionIndex publishes the mission topic).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from sitl_emu.navigator.mission import MissionNavigator, MissionSettings, Work, _Reach, _replace_kind
from sitl_emu.navigator.mission_items import Kind, NavItem
from sitl_emu.navigator.setpoint import NavInput
from sitl_emu.px4 import Severity
from sitl_emu.types import NAN


def closest_position_item(items: tuple[NavItem, ...], nav: NavInput) -> int:
    """setMissionToClosestItem: the position item nearest the vehicle in 3D, -1 if there is none."""
    best, best_dist = -1, math.inf
    x, y, z = nav.pos_ned_m
    for index, item in enumerate(items):
        if not item.has_position:
            continue
        tx, ty, tz = item.target_ned_m
        dist = math.sqrt((tx - x) ** 2 + (ty - y) ** 2 + (tz - z) ** 2)
        if dist < best_dist:
            best, best_dist = index, dist
    return best


def previous_position_index(items: tuple[NavItem, ...], seq: int) -> int | None:
    """findPreviousPositionIndex: the last position item before `seq`, None if there is none."""
    for index in range(min(seq, len(items)) - 1, -1, -1):
        if items[index].has_position:
            return index
    return None


def next_position_index(items: tuple[NavItem, ...], seq: int) -> int | None:
    """findNextPositionIndex: the first position item from `seq` on, None if there is none."""
    for index in range(max(seq, 0), len(items)):
        if items[index].has_position:
            return index
    return None


def reverse_start_index(items: tuple[NavItem, ...], mission_seq_prior_rtl: int, nav: NavInput) -> int:
    """RtlMissionFastReverse::on_activation: the item before the one the mission flew, or the closest one."""
    if mission_seq_prior_rtl < 0:
        return closest_position_item(items, nav)
    return max(mission_seq_prior_rtl - 1, 0)


def forward_start_index(items: tuple[NavItem, ...], mission_seq_prior_rtl: int, nav: NavInput) -> int:
    """RtlMissionFast::on_activation: the first position item from the one the mission flew (none left: the land
    item), or the closest one; -1 when there is nothing to fly."""
    if mission_seq_prior_rtl < 0:
        return closest_position_item(items, nav)
    index = next_position_index(items, mission_seq_prior_rtl)
    if index is not None:
        return index
    land = next((i for i, it in enumerate(items) if it.kind is Kind.LAND), -1)
    return land if land > 0 else -1


@dataclass(slots=True)
class ReturnNavigator(MissionNavigator):
    """MissionBase as RtlBase uses it: the parent's reach rules, jumps, texts and landing; the subclasses choose the
    next item (and the reverse one the active items)."""

    def start(self, nav: NavInput, s: MissionSettings, start_seq: int) -> None:
        """on_activation: from `start_seq`; already landed, or nothing to fly: the planned item is invalid."""
        if start_seq < 0 or nav.landed:
            self._planned_valid = False
            self._say("No valid mission available, refusing takeoff" if nav.landed
                      else "No valid mission available, loitering", Severity.CRITICAL)
            self.result.seq_current = max(start_seq, 0)
            self._end_of_mission(nav, s)
            return
        self.activate(nav, s, start_seq)  # "Executing Mission"

    def _climb_needed(self, nav: NavInput, s: MissionSettings, seq: int) -> float:
        return NAN  # the return types' setActiveMissionItems have no handleTakeoff

    def _next_index(self, seq: int) -> int | None:
        raise NotImplementedError

    def _advance(self, nav: NavInput) -> None:
        """setNextMissionItem: the next position item the way the return goes; none left: the return is over."""
        if self._work is not Work.DEFAULT:
            return
        following = self._next_index(self.result.seq_current)
        if following is None:
            self._say("Mission finished, landed" if nav.landed else "Mission finished, loitering")
            self._active = self._planned_valid = False
            return
        self.result.seq_current = following


@dataclass(slots=True)
class ForwardMissionNavigator(ReturnNavigator):
    """RtlMissionFast: on to the mission's landing, every position item a plain waypoint (the parent's triplet, its
    move to the land item and its landing)."""

    def load(self, items: tuple[NavItem, ...], current_seq: int, nav: NavInput | None = None,
             s: MissionSettings | None = None) -> None:
        super(ForwardMissionNavigator, self).load(tuple(_as_waypoint(it) if it.has_position and it.kind is not Kind.LAND
                                                        else it for it in items), current_seq, nav, s)

    def _next_index(self, seq: int) -> int | None:
        return next_position_index(self.items, seq + 1)


@dataclass(slots=True)
class ReverseMissionNavigator(ReturnNavigator):
    """RtlMissionFastReverse: back to the start, then home."""

    def _next_index(self, seq: int) -> int | None:
        return previous_position_index(self.items, seq)

    def _set_items(self, nav: NavInput, s: MissionSettings) -> None:
        """RtlMissionFastReverse::setActiveMissionItems."""
        seq = self._item_to_fly(nav, s)
        if seq is None:
            return
        item, work = self.items[seq], Work.DEFAULT
        if item.has_position:
            before = previous_position_index(self.items, seq)
            old = self.current
            if item.kind is Kind.TAKEOFF or before is None:
                item, work = self._landing(item, nav, s)
                self.previous = old if work is Work.CLIMB else None
            else:
                item = _as_waypoint(item)
                self.previous = old
            self.current = self._setpoint(item, nav, s)
            self.next = self._setpoint(self.items[before], nav, s) if before is not None else None
        self._issue(item)
        self._item, self._work = item, work
        self._reach = _Reach()

    def _landing(self, item: NavItem, nav: NavInput, s: MissionSettings) -> tuple[NavItem, Work]:
        """handleLanding: to the takeoff item first (a climb work item), then home: moved to at the current
        altitude when farther than NAV_ACC_RAD, landed on."""
        if self._work is Work.DEFAULT:
            return _replace_kind(item, Kind.WAYPOINT), Work.CLIMB
        home = nav.home_ned_m
        if math.hypot(home[0] - nav.pos_ned_m[0], home[1] - nav.pos_ned_m[1]) > s.acc_rad:
            move = NavItem(seq=item.seq, command=item.command, kind=Kind.WAYPOINT,
                           target_ned_m=(home[0], home[1], nav.pos_ned_m[2]), relative_alt_m=NAN, hold_s=0.0,
                           acceptance_m=NAN, yaw_rad=NAN, autocontinue=True, params=item.params)
            return move, Work.MOVE_TO_LAND
        land = NavItem(seq=item.seq, command=item.command, kind=Kind.LAND, target_ned_m=home, relative_alt_m=0.0,
                       hold_s=0.0, acceptance_m=NAN, yaw_rad=NAN, autocontinue=True, params=item.params)
        return land, Work.DEFAULT


@dataclass(slots=True)
class MissionLandNavigator(ForwardMissionNavigator):
    """RtlDirectMissionLand (rtl_direct_mission_land.cpp, RTL_TYPE 1 and 3): from the mission's land start, a climb
    first when below the return altitude, then on as RtlMissionFast flies (the land item moved to at the current
    altitude)."""

    rtl_up_m: float = NAN  # the return altitude (up, local frame)
    rtl_alt_amsl_m: float = NAN  # the same, AMSL, for the text

    def _climb_needed(self, nav: NavInput, s: MissionSettings, seq: int) -> float:
        """on_activation: climb when lower than the return altitude."""
        return self.rtl_up_m if -nav.pos_ned_m[2] < self.rtl_up_m else NAN

    def _set_items(self, nav: NavInput, s: MissionSettings) -> None:
        """setActiveMissionItems: the climb, a waypoint above the vehicle at the return altitude, before anything
        else (MISSION_CURRENT shows the land start meanwhile; its end is not reported reached)."""
        if not (math.isfinite(self._climb_up_m) and self._work is Work.DEFAULT and self._active):
            super(MissionLandNavigator, self)._set_items(nav, s)
            return
        start = self.items[self.result.seq_current]
        target = (nav.pos_ned_m[0], nav.pos_ned_m[1], -self._climb_up_m)
        climb = NavItem(seq=start.seq, command=start.command, kind=Kind.WAYPOINT, target_ned_m=target,
                        relative_alt_m=NAN, hold_s=0.0, acceptance_m=NAN, yaw_rad=NAN, autocontinue=True,
                        params=start.params)
        self._say(f"RTL Mission land: climb to {math.ceil(self.rtl_alt_amsl_m):d} m")
        self._climb_up_m = NAN
        self.current, self.next = self._setpoint(climb, nav, s), None
        self._item, self._work = climb, Work.CLIMB
        self._reach = _Reach()

    def _takeoff_and_land(self, item: NavItem, nav: NavInput, s: MissionSettings) -> tuple[NavItem, Work]:
        """RtlDirectMissionLand::handleLanding: the move to the land item at the vehicle's altitude."""
        if item.kind is Kind.LAND and not nav.landed and self._work is Work.DEFAULT:
            dx, dy = item.target_ned_m[0] - nav.pos_ned_m[0], item.target_ned_m[1] - nav.pos_ned_m[1]
            if math.hypot(dx, dy) > s.acc_rad:
                target = (item.target_ned_m[0], item.target_ned_m[1], nav.pos_ned_m[2])
                return replace(item, kind=Kind.WAYPOINT, target_ned_m=target, relative_alt_m=NAN, hold_s=0.0,
                               acceptance_m=NAN, yaw_rad=NAN, autocontinue=True), Work.MOVE_TO_LAND
        return item, Work.DEFAULT


def _as_waypoint(item: NavItem) -> NavItem:
    """A position item flown on the way back: a waypoint (LOITER_TO_ALT stays one already), no hold, continuing."""
    return NavItem(seq=item.seq, command=item.command, kind=Kind.WAYPOINT, target_ned_m=item.target_ned_m,
                   relative_alt_m=item.relative_alt_m, hold_s=0.0, acceptance_m=item.acceptance_m,
                   yaw_rad=item.yaw_rad, autocontinue=True, params=item.params)

