"""The vehicle's geofence and rally-point glue: the stored plans, the parameters and the estimate turned into the
navigator's geofence check (navigator/geofence_monitor.py) and RTL's destination (navigator/rally.py).

Vehicle.step calls `FenceChecks.check_commands` on the navigator's new requests (DO_REPOSITION and
DO_CHANGE_ALTITUDE targets outside the fence are refused, navigator_main.cpp geofence_allows_position) and
`FenceChecks.step` before each commander cycle (PX4: the navigator's geofence_breach_check
publishes geofence_result, the commander's health check and failsafe act on it); the mode executor asks
`rtl_destination` when Return starts (rtl.cpp setRtlTypeAndDestination on activation), and `FenceChecks.rtl_avoidance`
for the way around the fence to it (RtlDirect::on_activation: the geofence avoidance planner's path).
"""

from __future__ import annotations

from collections.abc import Callable

from sitl_emu.commander.commander import Commander
from sitl_emu.control.qmath import isfinite
from sitl_emu.geo import GeoRef, global_to_ned, ned_to_global
from sitl_emu.navigator.commands import NavCommand, NavCommandKind
from sitl_emu.navigator.geofence import (
    GF_ACTION_NONE,
    GF_ACTION_WARN,
    GeofenceSettings,
    GeoPoint,
    mission_fence_violation,
    point_allowed,
)
from sitl_emu.navigator.geofence_monitor import GeofenceInputs, GeofenceMonitor, geofence_settings
from sitl_emu.navigator.mission_store import PLAN_FENCE, PLAN_MISSION, PLAN_RALLY, MissionStore, Plan
from sitl_emu.navigator.rally import ReturnDestination, choose_destination, mission_landing
from sitl_emu.params import ParamRegistry
from sitl_emu.px4 import NavState, Severity
from sitl_emu.types import HomePosition, Vec3
from sitl_emu.vehicle.rtl_avoidance import RtlAvoidance

# emit(severity, module, text, is_event, statustext), as Vehicle._emit
Emit = Callable[[Severity, str, str, bool, bool], None]


def _geo(ref: GeoRef, pos_ned_m: Vec3) -> GeoPoint:
    lat_deg, lon_deg, alt_amsl_m = ned_to_global(ref, pos_ned_m)
    return GeoPoint(lat_deg, lon_deg, alt_amsl_m)


def home_point(c: Commander) -> GeoPoint | None:
    h = c.home
    return GeoPoint(h.lat_deg, h.lon_deg, h.alt_amsl_m) if h is not None else None


class FenceChecks:
    """The geofence monitor with its settings, read again only when a parameter changes."""

    def __init__(self, params: ParamRegistry) -> None:
        self.params = params
        self.monitor = GeofenceMonitor()
        self._settings: GeofenceSettings = geofence_settings(params)
        self._params_watch = params.changes.watch()  # params/changes.py
        self._mission_key: tuple[object, ...] | None = None  # what the mission was last checked against
        # the very objects that key was made of (plans and home are replaced, never changed in place): while they
        # are the same, the check is not due (PX4 checks again only when the mission, fence, home or a parameter
        # changes)
        self._checked_mission: Plan | None = None
        self._checked_fence: Plan | None = None
        self._checked_home: HomePosition | None = None
        self._checked_params = params.changes.watch(current=False)  # for the mission check: changed since it ran
        self.avoidance = RtlAvoidance(params)  # Return's way around the fence (rtl_avoidance.py)

    @property
    def settings(self) -> GeofenceSettings:
        if self._params_watch.changed():
            self._settings = geofence_settings(self.params)
        return self._settings

    def step(self, now_us: int, store: MissionStore, c: Commander, estimate_ned_m: Vec3, truth_ned_m: Vec3,
             ref: GeoRef, emit: Emit) -> None:
        """The navigator's geofence work before a commander cycle: the breach check when due, then the mission
        against the fence when a plan, home or a parameter was replaced."""
        fence = store.plan(PLAN_FENCE)
        if self.monitor.due(now_us, fence, position_valid=c.estimator_ready):  # as _breach_check's inputs
            self._breach_check(now_us, store, c, estimate_ned_m, truth_ned_m, ref, emit)
        if self._inputs_replaced(store.plan(PLAN_MISSION), fence, c):
            self._check_mission(store, c, emit)
        if self.monitor.fence.areas and c.estimator_ready and c.nav_state is not NavState.AUTO_RTL:
            self._track_avoidance(now_us, store, c, estimate_ned_m, ref, emit)

    def _track_avoidance(self, now_us: int, store: MissionStore, c: Commander, estimate_ned_m: Vec3, ref: GeoRef,
                         emit: Emit) -> None:
        """Return's way around the fence, kept up to date while a fence has areas (its own method: compiled, the
        lambda's closure would be built at every call of step)."""
        self.avoidance.track(now_us, self.monitor.fence.areas, estimate_ned_m,
                             lambda: rtl_target(estimate_ned_m, self.params, store, c, ref), ref, emit)

    def rtl_avoidance(self, pos_ned_m: Vec3, destination_ned_m: Vec3, ref: GeoRef,
                      emit: Emit) -> list[tuple[float, float]]:
        """The geofence avoidance path (north, east) from `pos_ned_m` to Return's destination, empty to fly there
        directly, around the fence in force."""
        return self.avoidance.path(self.monitor.fence.areas, pos_ned_m, destination_ned_m, ref, emit)

    def _breach_check(self, now_us: int, store: MissionStore, c: Commander, estimate_ned_m: Vec3,
                      truth_ned_m: Vec3, ref: GeoRef, emit: Emit) -> None:
        """One geofence check: the result goes to the commander (c.geofence), the texts out, and the Hold position
        after a breach into the navigator's queue."""
        plan = store.plan(PLAN_FENCE)
        ready = c.estimator_ready
        inputs = GeofenceInputs(estimate=_geo(ref, estimate_ned_m) if ready else None,
                                gps=_geo(ref, truth_ned_m) if ready else None, home=home_point(c), landed=c.landed,
                                armed=c.armed, in_hold=c.nav_state is NavState.AUTO_LOITER)
        out = self.monitor.update(now_us, plan, self.settings, inputs)
        c.geofence = self.monitor.result
        for text in out.navigator_texts:
            emit(Severity.CRITICAL, "navigator", text, True, True)
        for text in out.health_texts:  # geofenceCheck.cpp's legacy mavlink_log_critical (no event: no tab)
            emit(Severity.CRITICAL, "commander", text, False, True)
        if out.reposition is not None:
            p = out.reposition
            c.nav_commands.append(NavCommand(NavCommandKind.REPOSITION, p.lat_deg, p.lon_deg, p.alt_amsl_m))

    def _check_mission(self, store: MissionStore, c: Commander, emit: Emit) -> None:
        """The mission against the fence, again whenever the mission, the fence, home or a parameter changed
        (mission_base.cpp check_mission_valid): a violation makes the mission invalid and is told once."""
        mission, fence = store.plan(PLAN_MISSION), store.plan(PLAN_FENCE)
        key = (mission.opaque_id, mission.count, fence.opaque_id, fence.count, home_point(c), self.params.version)
        if key == self._mission_key:
            return
        self._mission_key = key
        text = self.mission_violation(store, c) if mission.count else None
        store.fence_violation = text
        if text is not None:
            emit(Severity.CRITICAL, "navigator", text, True, True)

    def _inputs_replaced(self, mission: Plan, fence: Plan, c: Commander) -> bool:
        """Whether a plan, home or the parameters were replaced since the last call (maybe with equal values)."""
        params_changed = self._checked_params.changed()
        if (not params_changed and mission is self._checked_mission and fence is self._checked_fence
                and c.home is self._checked_home):
            return False
        self._checked_mission, self._checked_fence, self._checked_home = mission, fence, c.home
        return True

    def check_commands(self, c: Commander, ref: GeoRef, here_ned_m: Vec3, emit: Emit) -> None:
        """Drop a reposition or altitude change whose target the fence forbids (GF_ACTION other than None and
        Warning), with PX4's text; NaN coordinates mean the current ones. An allowed reposition ends the Hold latch
        after a breach."""
        s = self.settings
        if s.action in (GF_ACTION_NONE, GF_ACTION_WARN) or not c.armed:
            return
        here = _geo(ref, here_ned_m)
        kept = []
        for cmd in c.nav_commands:
            if cmd.kind is NavCommandKind.TAKEOFF:
                kept.append(cmd)
                continue
            has_xy = isfinite(cmd.lat_deg) and isfinite(cmd.lon_deg)
            target = GeoPoint(cmd.lat_deg if has_xy else here.lat_deg, cmd.lon_deg if has_xy else here.lon_deg,
                              cmd.alt_amsl_m if isfinite(cmd.alt_amsl_m) else here.alt_amsl_m)
            if point_allowed(self.monitor.fence, s, target, home_point(c)):
                kept.append(cmd)
                if cmd.kind is NavCommandKind.REPOSITION:
                    self.monitor.unlatch()
            else:
                what = "Reposition" if cmd.kind is NavCommandKind.REPOSITION else "Altitude change"
                emit(Severity.CRITICAL, "navigator", f"{what} is outside geofence", True, True)
        c.nav_commands[:] = kept

    def mission_violation(self, store: MissionStore, c: Commander) -> str | None:
        """MissionFeasibilityChecker::checkMissionAgainstGeofence for the stored mission against the fence in force:
        None, or the CRITICAL text the navigator logs (an event: module navigator) and the mission is not valid.
        PX4 runs it when the mission, the fence (geofence_id) or home changes (mission_base.cpp check_mission_valid)."""
        return mission_fence_violation(store.plan(PLAN_MISSION).items, self.monitor.fence, self.settings,
                                       home_point(c))


def rtl_destination(pos_ned_m: Vec3, params: ParamRegistry, store: MissionStore, c: Commander,
                    ref: GeoRef) -> ReturnDestination | None:
    """RTL's destination in NED with its yaw (a rally point or the mission's landing), or None to return home."""
    home = home_point(c)
    if home is None or c.home is None:
        return None
    here = _geo(ref, pos_ned_m)
    landing = mission_landing(store.plan(PLAN_MISSION).items, store.mission_valid, home.alt_amsl_m)
    dest = choose_destination(int(params["RTL_TYPE"]), store.plan(PLAN_RALLY).items, home, c.home.yaw_rad, here,
                              landing)
    if dest.point == home and not dest.mission_land:
        return None
    p = dest.point
    return ReturnDestination(global_to_ned(ref, p.lat_deg, p.lon_deg, p.alt_amsl_m), dest.yaw_rad, dest.mission_land)


def rtl_target(pos_ned_m: Vec3, params: ParamRegistry, store: MissionStore, c: Commander, ref: GeoRef) -> Vec3:
    """Where Return would go from `pos_ned_m`: the rally point chosen, else home (the local origin without one)."""
    destination = rtl_destination(pos_ned_m, params, store, c, ref)
    if destination is not None:
        return destination[0]
    return c.home.pos_ned_m if c.home is not None else (0.0, 0.0, 0.0)
