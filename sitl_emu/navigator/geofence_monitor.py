"""The navigator's geofence check over time: the fence rebuilt when the fence plan changes, the breach checked every
200 ms, and the Hold position after a breach. Pure (no MAVLink, no clock: `now_us` comes in).

After src/modules/navigator/navigator_main.cpp (geofence_breach_check, PX4 main 2026-08) and geofence.cpp (run /
_updateFence when mission.geofence_id changes):
- every 200 ms, with a valid position (GF_SOURCE 0: the global position estimate; 1: raw GPS, here the true
  position), the three flags of geofence_result: beyond GF_MAX_HOR_DIST, above GF_MAX_VER_DIST, outside the fence;
- no prediction: PX4 main checks the current position only. GF_PREDICT (the braking-distance prediction) was
  removed with the geofence breach avoidance in PX4 commit ece74e8d24 (#27465, 2026-06) and is no PX4 parameter now;
- with GF_ACTION Hold, at the first breach while armed, the navigator sends a reposition to the current position (the
  Hold flies back to where the breach was seen) and latches: while it loiters after the breach the flags can be set
  but not cleared (so hovering at the boundary does not toggle the failsafe), until it leaves Hold (100 ms after);
- the commander (geofenceCheck.cpp) makes geofence_breached of the flags and GF_ACTION, logs one CRITICAL text per
  flag when its report changes, and the failsafe acts (commander/geofence_failsafe.py).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Final

from sitl_emu.navigator.geofence import (
    GF_ACTION_HOLD,
    GF_SOURCE_GPS,
    NO_BREACH,
    Geofence,
    GeofenceResult,
    GeofenceSettings,
    GeoPoint,
    below_max_alt,
    build_fence,
    closer_than_max_dist,
)
from sitl_emu.navigator.mission_store import Plan
from sitl_emu.params import ParamRegistry

CHECK_INTERVAL_US: Final = 200_000  # GEOFENCE_CHECK_INTERVAL_US
LATCH_RELEASE_US: Final = 100_000


def geofence_settings(p: ParamRegistry) -> GeofenceSettings:
    return GeofenceSettings(action=int(p["GF_ACTION"]), source=int(p["GF_SOURCE"]),
                            max_hor_dist_m=float(p["GF_MAX_HOR_DIST"]), max_ver_dist_m=float(p["GF_MAX_VER_DIST"]))


@dataclass(slots=True)
class GeofenceInputs:
    """What the navigator sees at a check: positions (None while not valid), home (None while not set), state.
    Made at every check, so not frozen, its `__init__` written out (ARCHITECTURE.md, On the tick path); read-only by
    convention."""

    estimate: GeoPoint | None
    gps: GeoPoint | None
    home: GeoPoint | None
    landed: bool
    armed: bool
    in_hold: bool  # nav_state AUTO_LOITER

    def __init__(self, estimate: GeoPoint | None, gps: GeoPoint | None, home: GeoPoint | None, landed: bool,
                 armed: bool, in_hold: bool) -> None:
        self.estimate = estimate
        self.gps = gps
        self.home = home
        self.landed = landed
        self.armed = armed
        self.in_hold = in_hold


@dataclass(slots=True)
class GeofenceStep:
    """What one update produced: texts for the navigator (fence discarded) and the commander (breach report), and a
    Hold position to fly to (GF_ACTION Hold, first breach)."""

    navigator_texts: list[str] = field(default_factory=list)
    health_texts: list[str] = field(default_factory=list)
    reposition: GeoPoint | None = None

    def __init__(self, navigator_texts: list[str] | None = None, health_texts: list[str] | None = None,
                 reposition: GeoPoint | None = None) -> None:
        """Written out (made at every check; ARCHITECTURE.md, On the tick path); None stands for a new empty list."""
        self.navigator_texts = navigator_texts if navigator_texts is not None else []
        self.health_texts = health_texts if health_texts is not None else []
        self.reposition = reposition


class GeofenceMonitor:
    """The navigator's Geofence plus geofence_breach_check, and the commander's view of its result."""

    def __init__(self) -> None:
        self.fence = Geofence()
        self.result: GeofenceResult = NO_BREACH
        # the fence plan in force: its CRC32 and item count (-1: none yet, never a plan's), compared every cycle
        self._plan_id, self._plan_count = -1, -1
        self._last_check_us: int | None = None
        self._latched_at_us = 0  # _time_loitering_after_gf_breach (0: not latched)
        self._reposition_sent = False

    def due(self, now_us: int, plan: Plan, position_valid: bool = True) -> bool:
        """Whether `update` would do anything now (the caller may skip building its inputs otherwise). Without a
        valid position (`update` gets None for it) only a new fence plan or the post-breach latch need an update."""
        if self._new_plan(plan) or self._latched_at_us:
            return True
        return position_valid and (self._last_check_us is None or now_us - self._last_check_us > CHECK_INTERVAL_US)

    def _new_plan(self, plan: Plan) -> bool:
        return plan.opaque_id != self._plan_id or plan.count != self._plan_count

    def update(self, now_us: int, plan: Plan, s: GeofenceSettings, inp: GeofenceInputs) -> GeofenceStep:
        step = GeofenceStep()
        if self._new_plan(plan):  # navigator_main: mission.geofence_id changed -> updateFence
            self._plan_id, self._plan_count = plan.opaque_id, plan.count
            self.fence, step.navigator_texts = build_fence(plan.items, home=inp.home, position=inp.estimate,
                                                           landed=inp.landed, action=s.action)
        if not inp.in_hold and self._latched_at_us and now_us - self._latched_at_us > LATCH_RELEASE_US:
            self._latched_at_us = 0
        if self._last_check_us is not None and now_us - self._last_check_us <= CHECK_INTERVAL_US:
            return step
        point = inp.gps if s.source == GF_SOURCE_GPS else inp.estimate
        if point is None:
            return step
        self._last_check_us = now_us
        before = self.result
        self.result = self._flags(point, s, inp.home)
        texts = self.result.health_texts()
        if texts and texts != before.health_texts():  # the commander's report changed (a flag, or GF_ACTION)
            step.health_texts = texts
        step.reposition = self._hold_reposition(now_us, s, inp)
        return step

    def unlatch(self) -> None:
        """A manual reposition ends the post-breach latch (navigator_main.cpp DO_REPOSITION)."""
        self._latched_at_us = 0

    def _flags(self, point: GeoPoint, s: GeofenceSettings, home: GeoPoint | None) -> GeofenceResult:
        dist = not closer_than_max_dist(s, point, home)
        alt = not below_max_alt(s, point.alt_amsl_m, home)
        custom = not self.fence.inside_areas(point.lat_deg, point.lon_deg)
        if self._latched_at_us:  # while loitering after a breach: set, never cleared
            old = self.result
            dist, alt, custom = dist or old.max_dist, alt or old.max_alt, custom or old.custom
        return GeofenceResult(dist, alt, custom, s.action)

    def _hold_reposition(self, now_us: int, s: GeofenceSettings, inp: GeofenceInputs) -> GeoPoint | None:
        if not self.result.triggered:
            self._reposition_sent = False
            return None
        if self._reposition_sent or inp.estimate is None or not inp.armed or s.action != GF_ACTION_HOLD:
            return None
        self._reposition_sent = True
        self._latched_at_us = now_us
        return inp.estimate
