"""AUTO.MISSION's navigator: which item is current, when it is reached, what comes next (pure; time in NavInput).

Written from PX4's src/modules/navigator/mission_base.cpp (on_activation, on_active, advance_mission,
set_mission_items, setEndOfMissionItems, checkClimbRequired, getNonJumpItem), mission.cpp (setActiveMissionItems,
handleTakeoff), mission_block.cpp (is_mission_item_reached_or_completed, mission_item_to_position_setpoint) for a
multicopter:
- on activation on the ground (or below the first position item by more than NAV_MC_ALT_RAD) a climb is inserted:
  "Climb to %.1f meters above home", a takeoff straight up; its end is not reported as reached, and a TAKEOFF item
  is then flown as a waypoint;
- a position item is reached within its acceptance radius (param2, else NAV_ACC_RAD) and NAV_MC_ALT_RAD, a takeoff
  by altitude only, a land item when landed; then the heading (finite item yaw: within MIS_YAW_ERR) and the hold
  time (param1) must pass; DO_* items and RETURN_TO_LAUNCH complete at once (processed in the same cycle here, so
  only the last of them is reported, as PX4's mission_result is read once per MAVLink cycle);
- the triplet: previous position, current, next position item (none while a hold time or delay brakes); DO_JUMP is
  followed while its repeat count lasts (the counts reset when the mission completes);
- at the end: "Mission finished, loitering" (or ", landed") and loiter at the last setpoint.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from enum import Enum

from sitl_emu.motion_planning.heading import wrap_pi
from sitl_emu.navigator.mission_items import Kind, NavItem
from sitl_emu.navigator.setpoint import NavInput, SetpointType
from sitl_emu.px4 import MavCmd, Severity
from sitl_emu.types import NAN, Vec3

MAX_INSTANT_ITEMS = 32  # DO_* items handled in one cycle at most (a DO_JUMP loop without positions stops here)
_INSTANT = frozenset({Kind.ACTION, Kind.RTL, Kind.JUMP})


class Work(Enum):
    """PX4's WorkItemType, the parts a multicopter uses."""

    DEFAULT = "default"
    CLIMB = "climb"
    MOVE_TO_LAND = "move_to_land"


@dataclass(frozen=True, slots=True)
class MissionSettings:
    acc_rad: float  # NAV_ACC_RAD
    alt_rad: float  # NAV_MC_ALT_RAD
    yaw_err_rad: float  # MIS_YAW_ERR
    yaw_timeout_s: float  # MIS_YAW_TMT


@dataclass(frozen=True, slots=True)
class Setpoint:
    """position_setpoint_s: where, which type, heading (NaN: FlightTaskAuto's), acceptance radius, cruise speed."""

    kind: SetpointType
    target_ned_m: Vec3
    yaw_rad: float
    acceptance_m: float
    cruise_m_s: float
    loiter: bool = False  # SETPOINT_TYPE_LOITER: FlightTaskAuto takes no next waypoint


@dataclass(slots=True)
class Result:
    """mission_result_s: what the MAVLink side reports."""

    seq_current: int = 0
    seq_reached: int = -1
    finished: bool = False
    valid: bool = True


@dataclass(slots=True)
class _Reach:
    position: bool = False
    yaw: bool = False
    since_us: int = 0


@dataclass(slots=True)
class MissionNavigator:
    """The mission's state across activations (PX4 keeps one Mission object for the whole flight)."""

    items: tuple[NavItem, ...] = ()
    result: Result = field(default_factory=Result)
    messages: list[tuple[Severity, str]] = field(default_factory=list)
    wants_rtl: bool = False  # the RTL item's vehicle_command, for the commander
    previous: Setpoint | None = None
    current: Setpoint | None = None
    next: Setpoint | None = None
    _active: bool = False  # PX4's _mission_type == MISSION_TYPE_MISSION
    _planned_valid: bool = True  # _is_current_planned_mission_item_valid: false once the mission ran out of items
    _work: Work = Work.DEFAULT
    _item: NavItem | None = None
    _climb_up_m: float = NAN
    _reach: _Reach = field(default_factory=_Reach)
    _jumps: dict[int, int] = field(default_factory=dict)
    _cruise: float = NAN
    _roi: Vec3 | None = None

    def load(self, items: tuple[NavItem, ...], current_seq: int, nav: NavInput | None = None,
             s: MissionSettings | None = None) -> None:
        """A new plan (upload or clear): the result starts over; while the mission flies (`nav` given), the vehicle
        goes on with the new plan's current item at once (MissionBase::onMissionUpdate)."""
        flying = self._active and nav is not None and s is not None
        self.items, self._jumps = items, {}
        self.result = Result(seq_current=current_seq)
        self._active, self._planned_valid = flying and bool(items), True
        if flying and nav is not None and s is not None:
            self._work = Work.DEFAULT
            self._set_items(nav, s)

    def reset_jump_counters(self) -> None:
        """DO_SET_MISSION_CURRENT param2 = 1: the DO_JUMP repeat counts and the completion flag start over."""
        self._jumps = {}
        self.result.finished = False

    def set_current(self, seq: int, nav: NavInput | None, s: MissionSettings) -> None:
        """MISSION_SET_CURRENT / MISSION_START(n) (Mission::set_current_mission_index): the same item keeps
        everything; another one becomes current, and while flying the vehicle turns to it at once (the triplet is
        reset: no line from the old item)."""
        if seq == self.result.seq_current and not self.result.finished:
            return
        self.result.seq_current = seq
        self.result.finished = False
        self._planned_valid = True
        if nav is not None and self._active:
            self.previous = self.current = self.next = None
            self._work = Work.DEFAULT
            self._set_items(nav, s)

    # ---- activation ---------------------------------------------------------------------------------------------
    def activate(self, nav: NavInput, s: MissionSettings, current_seq: int) -> None:
        """MissionBase::on_activation (each activation follows an inactivation, which ends the mission type, so
        "Executing Mission" is said again on a resume): from the current item; a finished mission loiters unless
        MISSION_START / SET_CURRENT chose an item, or the vehicle is back on the ground (checkMissionRestart)."""
        self.result.seq_current = current_seq
        if not self._planned_valid and nav.landed and current_seq + 1 >= len(self.items):
            # checkMissionRestart: a mission flown to its end restarts from the first item once back on the ground
            self.result.seq_current, self._planned_valid, self._jumps = 0, True, {}
        self.previous = self.current = self.next = None
        self._roi, self._cruise = None, NAN
        self.wants_rtl = False
        for done in self.items[:self.result.seq_current]:  # replayCachedSpeedChangeItems: a resume keeps the speed
            if done.command == MavCmd.DO_CHANGE_SPEED:
                self._issue(done)
        if not self.items:
            self._say("No valid mission available, refusing takeoff" if nav.landed
                      else "No valid mission available, loitering", Severity.CRITICAL)
            self._active = False
        else:
            self._say("Executing Mission")
            self._active = True
        self._work = Work.DEFAULT
        self._climb_up_m = self._climb_needed(nav, s, self.result.seq_current)
        self._set_items(nav, s)

    def _climb_needed(self, nav: NavInput, s: MissionSettings, seq: int) -> float:
        """checkClimbRequired: the next position item's altitude if it is above us by more than NAV_MC_ALT_RAD."""
        item = self._next_position(seq)
        if item is None:
            return NAN
        if -item.target_ned_m[2] - -nav.pos_ned_m[2] > s.alt_rad:
            return -item.target_ned_m[2]
        return NAN

    # ---- every cycle --------------------------------------------------------------------------------------------
    def update(self, nav: NavInput, s: MissionSettings) -> None:
        """MissionBase::on_active: reached -> report, advance, load the next items (instant items at once)."""
        for _ in range(MAX_INSTANT_ITEMS):
            if not self._active or not self._reached(nav, s):
                break
            if self._work is not Work.CLIMB:
                self.result.seq_reached = self.result.seq_current
            self._reach = _Reach()
            if self._item is not None and not self._item.autocontinue:
                break
            self._advance(nav)
            self._set_items(nav, s)
            if self._item is None or self._item.kind not in _INSTANT:
                break  # a flown item is checked from the next cycle on
        self._roi_heading(nav, s)

    def _advance(self, nav: NavInput) -> None:
        """advance_mission: the next item, unless a work item (climb, move to land) of this one is running."""
        if self._work is not Work.DEFAULT:
            return
        nxt = self._resolve(self.result.seq_current + 1, consume=True)
        if nxt is None:
            self._say("Mission finished, landed" if nav.landed else "Mission finished, loitering")
            if self.result.seq_current + 1 >= len(self.items):
                self._jumps = {}
            self._active = self._planned_valid = False
            return
        self.result.seq_current = nxt

    # ---- items --------------------------------------------------------------------------------------------------
    def _resolve(self, index: int, consume: bool) -> int | None:
        """getNonJumpItem: the first item from `index` that is not a DO_JUMP, following jumps while their repeat
        count lasts (`consume`: count this pass)."""
        for _ in range(len(self.items) + 1):
            if not 0 <= index < len(self.items):
                return None
            item = self.items[index]
            if item.kind is not Kind.JUMP:
                return index
            target, repeats = int(item.params[0]), int(item.params[1])
            done = self._jumps.get(index, 0)
            if done < repeats and 0 <= target < len(self.items):
                if consume:
                    self._jumps[index] = done + 1
                index = target
            else:
                index += 1
        return None

    def _next_position(self, start: int) -> NavItem | None:
        """The first item with a position from `start` on (jumps followed without counting)."""
        index: int | None = start
        for _ in range(len(self.items)):
            index = self._resolve(index, consume=False) if index is not None else None
            if index is None:
                return None
            if self.items[index].has_position:
                return self.items[index]
            index += 1
        return None

    def _item_to_fly(self, nav: NavInput, s: MissionSettings) -> int | None:
        """The current item once jumps are resolved, made current; None at the end of the mission (handled)."""
        seq = self._resolve(self.result.seq_current, consume=False) if self._active and self._planned_valid else None
        if seq is None:
            self._end_of_mission(nav, s)
        else:
            self.result.seq_current = seq
        return seq

    def _set_items(self, nav: NavInput, s: MissionSettings) -> None:
        """set_mission_items + setActiveMissionItems."""
        seq = self._item_to_fly(nav, s)
        if seq is None:
            return
        item = self.items[seq]
        old = self.current
        work = Work.DEFAULT
        if item.has_position:
            original = item
            item, work = self._takeoff_and_land(item, nav, s)
            self.current = self._setpoint(item, nav, s)
            self.next = self._next_setpoint(original, item, work, nav, s)
        elif item.kind is Kind.DELAY:
            self.next = None
        self._issue(item)
        if self.current is not old and old is not None and self._work is not Work.MOVE_TO_LAND:
            self.previous = old
        self._item, self._work = item, work
        self._reach = _Reach()

    def _next_setpoint(self, original: NavItem, item: NavItem, work: Work, nav: NavInput,
                       s: MissionSettings) -> Setpoint | None:
        """The triplet's next: the item itself after a climb or a move to land, else the next position item; none
        where the vehicle must stop (no autocontinue, a hold time: brake_for_hold)."""
        if not item.autocontinue or item.hold_s > 0.0:
            return None
        if work is Work.CLIMB:
            nxt: NavItem | None = _replace_kind(original, Kind.WAYPOINT)
        elif work is Work.MOVE_TO_LAND:
            nxt = original
        else:
            nxt = self._next_position(original.seq + 1)
        return None if nxt is None else self._setpoint(nxt, nav, s)

    def _takeoff_and_land(self, item: NavItem, nav: NavInput, s: MissionSettings) -> tuple[NavItem, Work]:
        """handleTakeoff / handleLanding for a multicopter: the climb before the mission, a takeoff item flown as a
        waypoint once airborne, a land item preceded by a move to it at the current altitude."""
        if math.isfinite(self._climb_up_m) and self._work is Work.DEFAULT:
            home_up = -nav.home_ned_m[2]
            self._say(f"Climb to {self._climb_up_m - home_up:.1f} meters above home")
            climb = NavItem(seq=item.seq, command=item.command, kind=Kind.TAKEOFF if nav.landed else Kind.WAYPOINT,
                            target_ned_m=(nav.pos_ned_m[0], nav.pos_ned_m[1], -self._climb_up_m),
                            relative_alt_m=self._climb_up_m - home_up, hold_s=0.0, acceptance_m=NAN, yaw_rad=NAN,
                            autocontinue=True, params=item.params)
            self._climb_up_m = NAN
            return climb, Work.CLIMB
        if item.kind is Kind.TAKEOFF and (self._work is Work.CLIMB or not nav.landed):
            return _replace_kind(item, Kind.WAYPOINT), Work.DEFAULT
        if item.kind is Kind.LAND and not nav.landed and self._work is Work.DEFAULT:
            dx, dy = item.target_ned_m[0] - nav.pos_ned_m[0], item.target_ned_m[1] - nav.pos_ned_m[1]
            if math.hypot(dx, dy) > s.acc_rad:
                z = self.current.target_ned_m[2] if self.current is not None else nav.pos_ned_m[2]
                move = NavItem(seq=item.seq, command=item.command, kind=Kind.WAYPOINT,
                               target_ned_m=(item.target_ned_m[0], item.target_ned_m[1], z), relative_alt_m=NAN,
                               hold_s=0.0, acceptance_m=NAN, yaw_rad=NAN, autocontinue=True, params=item.params)
                return move, Work.MOVE_TO_LAND
        return item, Work.DEFAULT

    def _setpoint(self, item: NavItem, nav: NavInput, s: MissionSettings) -> Setpoint:
        """mission_item_to_position_setpoint."""
        acc = item.acceptance_m if math.isfinite(item.acceptance_m) and item.acceptance_m > 1e-6 else s.acc_rad
        kind = SetpointType.POSITION
        yaw = item.yaw_rad
        if item.kind is Kind.TAKEOFF and nav.landed:
            kind, yaw = SetpointType.TAKEOFF, NAN
        elif item.kind is Kind.LAND:
            kind, yaw = SetpointType.LAND, NAN
        loiter = item.kind in (Kind.LOITER_TIME, Kind.LOITER_UNLIM)
        return Setpoint(kind, item.target_ned_m, yaw, acc, self._cruise, loiter)

    def _issue(self, item: NavItem) -> None:
        """issue_command and the navigator's handling of the DO_* commands it gets back."""
        if item.kind is Kind.RTL:
            self.wants_rtl = True
        elif item.command == MavCmd.DO_CHANGE_SPEED:
            speed = item.params[1]
            self._cruise = speed if speed > 0.0 else NAN  # -1 (or 0): back to the default cruise speed
            self._apply_cruise()
        elif item.command == MavCmd.DO_SET_ROI_LOCATION:
            self._roi = item.target_ned_m
        elif item.command == MavCmd.DO_SET_ROI_NONE:
            self._roi = None

    def _apply_cruise(self) -> None:
        self.current = _with_cruise(self.current, self._cruise)
        self.next = _with_cruise(self.next, self._cruise)

    def _end_of_mission(self, nav: NavInput, s: MissionSettings) -> None:
        """setEndOfMissionItems: idle on the ground, else loiter at the current setpoint (or here)."""
        cur = self.current
        if nav.landed:
            self.current = Setpoint(SetpointType.IDLE, nav.pos_ned_m, NAN, s.acc_rad, NAN)
        elif cur is None or cur.kind not in (SetpointType.POSITION,):
            self.current = Setpoint(SetpointType.POSITION, nav.pos_ned_m, nav.yaw_rad, s.acc_rad, NAN, True)
        else:
            self.current = Setpoint(SetpointType.POSITION, cur.target_ned_m, cur.yaw_rad, cur.acceptance_m,
                                    cur.cruise_m_s, True)
        self.previous = self.next = None
        self.result.finished = bool(self.items)
        self._active = False
        self._item = None

    # ---- reached ------------------------------------------------------------------------------------------------
    def _reached(self, nav: NavInput, s: MissionSettings) -> bool:
        """is_mission_item_reached_or_completed."""
        item = self._item
        if item is None:
            return False
        kind = item.kind
        if kind in _INSTANT:
            return True
        if kind is Kind.LAND:
            return nav.landed
        if kind is Kind.LOITER_UNLIM:
            return False
        r = self._reach
        if kind is Kind.DELAY and not r.position:
            r.position = r.yaw = True
            r.since_us = nav.time_us
        if not nav.landed and not r.position and self._position_reached(item, nav, s):
            r.position, r.since_us = True, nav.time_us
        if r.position and not r.yaw:
            r.yaw = not math.isfinite(item.yaw_rad) or abs(wrap_pi(item.yaw_rad - nav.yaw_rad)) < s.yaw_err_rad \
                or s.yaw_timeout_s >= 1e-6
        return r.position and r.yaw and nav.time_us >= r.since_us + int(item.hold_s * 1e6)

    def _position_reached(self, item: NavItem, nav: NavInput, s: MissionSettings) -> bool:
        tx, ty, tz = item.target_ned_m
        x, y, z = nav.pos_ned_m
        if item.kind is Kind.TAKEOFF:
            alt_rad = s.alt_rad
            if 0.0 < item.relative_alt_m < alt_rad:
                alt_rad = item.relative_alt_m / 2.0
            return -z > -tz - alt_rad
        acc = self.current.acceptance_m if self.current is not None else s.acc_rad
        return math.hypot(tx - x, ty - y) <= acc and abs(tz - z) <= s.alt_rad

    def _roi_heading(self, nav: NavInput, s: MissionSettings) -> None:
        """heading_sp_update with an ROI location: face it while farther than NAV_ACC_RAD (not in takeoff/land)."""
        cur, roi = self.current, self._roi
        if roi is None or cur is None or cur.kind is not SetpointType.POSITION or self._item is None:
            return
        dx, dy = roi[0] - nav.pos_ned_m[0], roi[1] - nav.pos_ned_m[1]
        if math.hypot(dx, dy) > s.acc_rad:
            yaw = math.atan2(dy, dx)
            self.current = Setpoint(cur.kind, cur.target_ned_m, yaw, cur.acceptance_m, cur.cruise_m_s, cur.loiter)

    def _say(self, text: str, severity: Severity = Severity.INFO) -> None:
        self.messages.append((severity, text))


def _replace_kind(item: NavItem, kind: Kind) -> NavItem:
    """The item flown as `kind` (a takeoff item as a waypoint: its yaw ignored, no hold)."""
    return replace(item, kind=kind, hold_s=0.0, yaw_rad=NAN)


def _with_cruise(sp: Setpoint | None, cruise_m_s: float) -> Setpoint | None:
    """The setpoint flown at `cruise_m_s` (DO_CHANGE_SPEED), or None without one."""
    if sp is None:
        return None
    return replace(sp, cruise_m_s=cruise_m_s)
