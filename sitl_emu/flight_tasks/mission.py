"""AUTO.MISSION as a navigator task: the mission navigator (navigator/mission.py) picks the items, this task turns its
position setpoint triplet into the waypoints FlightTaskAuto flies (core.AutoCore).

The navigator itself outlives the task (PX4 keeps one Mission object, so a paused mission resumes at its current
item): the executor owns it (MissionFlight) and hands it to each activation.
"""

from __future__ import annotations

import math

from sitl_emu.flight_tasks.core import Task, Waypoint
from sitl_emu.geo import GeoRef
from sitl_emu.navigator.mission import MissionNavigator, MissionSettings, Setpoint
from sitl_emu.navigator.mission_items import nav_items
from sitl_emu.navigator.mission_store import PLAN_MISSION, MissionStore
from sitl_emu.navigator.setpoint import NavInput, SetpointType
from sitl_emu.params import ParamRegistry
from sitl_emu.types import Vec3


def mission_settings(params: ParamRegistry) -> MissionSettings:
    def get(name: str, default: float) -> float:
        return float(params.get(name)) if name in params else default

    return MissionSettings(acc_rad=get("NAV_ACC_RAD", 10.0), alt_rad=get("NAV_MC_ALT_RAD", 0.8),
                           yaw_err_rad=math.radians(get("MIS_YAW_ERR", 12.0)), yaw_timeout_s=get("MIS_YAW_TMT", -1.0))


class MissionFlight:
    """The mission navigator with the stored plan it flies: a new upload (another plan id) or a MISSION_SET_CURRENT
    reaches it here."""

    def __init__(self, store: MissionStore) -> None:
        self.store = store
        self.navigator = MissionNavigator()
        self._plan_id: int | None = None
        self._items_ref: object = None
        self._changes_seen = store.current_changes
        self._resets_seen = store.jump_resets

    def sync(self, ref: GeoRef, home_alt_amsl_m: float, nav: NavInput | None, settings: MissionSettings) -> None:
        """Follow the store: a changed plan is loaded (relative altitudes above home), a new current item is set,
        the DO_JUMP counters start over."""
        plan = self.store.plan(PLAN_MISSION)
        if plan.items is not self._items_ref:
            self._items_ref = plan.items
            self.navigator.load(nav_items(plan.items, ref, home_alt_amsl_m), self.store.current_seq, nav, settings)
            self._changes_seen = self.store.current_changes
            self._publish()
        if self.store.current_changes != self._changes_seen:  # MISSION_SET_CURRENT or MISSION_START(n)
            self._changes_seen = self.store.current_changes
            self.navigator.set_current(self.store.current_seq, nav, settings)
            self._publish()
        if self.store.jump_resets != self._resets_seen:  # DO_SET_MISSION_CURRENT with param2 = 1
            self._resets_seen = self.store.jump_resets
            self.navigator.reset_jump_counters()
            self._publish()

    def _publish(self) -> None:
        """The navigator's mission_result into the store, for MISSION_CURRENT / MISSION_ITEM_REACHED."""
        r = self.navigator.result
        self.store.current_seq = r.seq_current
        self.store.seq_reached = r.seq_reached
        self.store.finished = r.finished

    def publish(self) -> None:
        self._publish()


class MissionTask(Task):
    """One activation of AUTO.MISSION."""

    def __init__(self, nav: NavInput, params: ParamRegistry, flight: MissionFlight, ref: GeoRef,
                 home_alt_amsl_m: float) -> None:
        super().__init__(nav, params)
        self._flight = flight
        self._ref, self._home_alt = ref, home_alt_amsl_m
        self._mission_settings = mission_settings(params)
        self._loiter_rad = float(params.get("NAV_LOITER_RAD")) if "NAV_LOITER_RAD" in params else 80.0
        flight.sync(ref, home_alt_amsl_m, None, self._mission_settings)
        flight.navigator.activate(nav, self._mission_settings, flight.store.current_seq)
        flight.publish()

    @property
    def wants_rtl(self) -> bool:
        """The RTL item asked the commander for Return (cleared when read)."""
        nav = self._flight.navigator
        wants, nav.wants_rtl = nav.wants_rtl, False
        return wants

    def end_loiter_point(self) -> Vec3 | None:
        """Where a finished mission loiters (its last setpoint, SETPOINT_TYPE_LOITER), else None: the Hold the
        commander switches to then keeps it (loiter.cpp set_loiter_position with can_loiter_at_sp)."""
        cur = self._flight.navigator.current
        if not self._flight.navigator.result.finished or cur is None or not cur.loiter:
            return None
        return cur.target_ned_m if _finite(cur.target_ned_m) else None

    def loiter_point(self, nav: NavInput) -> Vec3 | None:
        """The loiter setpoint the vehicle is established on (within NAV_ACC_RAD + NAV_LOITER_RAD), else None."""
        cur = self._flight.navigator.current
        if cur is None or not cur.loiter or not _finite(cur.target_ned_m):
            return None
        radius = self._mission_settings.acc_rad + self._loiter_rad
        dist = math.hypot(cur.target_ned_m[0] - nav.pos_ned_m[0], cur.target_ned_m[1] - nav.pos_ned_m[1])
        return cur.target_ned_m if dist <= radius else None

    def _waypoint(self, nav: NavInput) -> Waypoint:
        flight = self._flight
        flight.sync(self._ref, self._home_alt, nav, self._mission_settings)
        navigator = flight.navigator
        navigator.update(nav, self._mission_settings)
        flight.publish()
        for severity, text in navigator.messages:
            self._say(severity, text)
        navigator.messages.clear()
        return mission_waypoint(navigator.previous, navigator.current, navigator.next, nav)


def mission_waypoint(previous: Setpoint | None, current: Setpoint | None, nxt: Setpoint | None,
                     nav: NavInput) -> Waypoint:
    """FlightTaskAuto::_evaluatePositionSetpointTriplet: no previous -> the current one; no next (or a loiter) -> the
    current one."""
    if current is None:
        return Waypoint(SetpointType.POSITION, nav.pos_ned_m, nav.yaw_rad)
    target = current.target_ned_m
    prev = previous.target_ned_m if previous is not None and _finite(previous.target_ned_m) else target
    following = nxt.target_ned_m if nxt is not None and not current.loiter and _finite(nxt.target_ned_m) else target
    return Waypoint(current.kind, target, current.yaw_rad, current.cruise_m_s, prev, following, current.acceptance_m)


def _finite(v: tuple[float, float, float]) -> bool:
    return all(math.isfinite(c) for c in v)
