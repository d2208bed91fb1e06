"""The geofence: the uploaded fence plan as polygons and circles, GF_MAX_HOR_DIST / GF_MAX_VER_DIST around home, and
PX4's point tests. Pure: no MAVLink, no clock (the breach check over time is navigator/geofence_monitor.py).

After src/modules/navigator/geofence.cpp (PX4 main, 2026-08):
- _updateFence walks the stored fence items: a polygon starts at a POLYGON_VERTEX_INCLUSION/EXCLUSION item and
  takes the next `param1` (vertex count) items as its vertices, whatever they are; a CIRCLE_INCLUSION/EXCLUSION is
  one item (param1 = radius); a FENCE_RETURN_POINT or an unknown command is skipped. An area is discarded, with a
  CRITICAL text, if it does not contain home (home known), or if the vehicle flies (GF_ACTION not None) and it does
  not contain the vehicle.
- A point passes if it is inside every inclusion area and outside every exclusion area (areas combine with AND, so
  two inclusion polygons allow only their intersection), closer than GF_MAX_HOR_DIST to home and lower than
  GF_MAX_VER_DIST above home (0: off). An empty fence passes everything.
- The fence items' altitudes are stored and sent back but never used: the vertical limits _altitude_min/_max come
  only from a geofence.txt file, which the emulator does not read, so a MAVLink fence has no vertical bound.
- Inside a polygon: PNPOLY on raw lat/lon; a vertex in a non-global frame ends the test with the answer so far; a
  polygon whose vertices run past the end of the plan fails to load its first vertex and is never "inside". Inside a
  circle: both points projected around a reference fixed at the first point tested (MapProjection), distance squared
  below the radius squared (so a NaN radius contains nothing).
The mission check against the fence is MissionFeasibilityChecker::checkMissionAgainstGeofence
(navigator/mission_feasibility_checker.cpp): see `mission_fence_violation`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Final

from sitl_emu.geo import EARTH_RADIUS_M, GeoRef, global_to_ned
from sitl_emu.navigator.mission_store import MissionItem
from sitl_emu.px4 import GLOBAL_FRAMES, RELATIVE_FRAMES, MavCmd

_POLYGONS: Final = (MavCmd.NAV_FENCE_POLYGON_VERTEX_INCLUSION, MavCmd.NAV_FENCE_POLYGON_VERTEX_EXCLUSION)
_CIRCLES: Final = (MavCmd.NAV_FENCE_CIRCLE_INCLUSION, MavCmd.NAV_FENCE_CIRCLE_EXCLUSION)
_INCLUSIONS: Final = (MavCmd.NAV_FENCE_POLYGON_VERTEX_INCLUSION, MavCmd.NAV_FENCE_CIRCLE_INCLUSION)
_AREA_COMMANDS: Final = frozenset({*_POLYGONS, *_CIRCLES})

# GF_ACTION (geofence_params.yaml)
GF_ACTION_NONE, GF_ACTION_WARN, GF_ACTION_HOLD, GF_ACTION_RETURN, GF_ACTION_TERMINATE, GF_ACTION_LAND = range(6)
GF_SOURCE_GPS: Final = 1

TEXT_NO_HOME: Final = "Geofence invalid, doesn't contain Home position"
TEXT_NO_CURRENT: Final = "Geofence invalid, doesn't contain current vehicle position"


@dataclass(slots=True)
class GeoPoint:
    """A global position; read-only by convention (made at every geofence check: ARCHITECTURE.md, On the tick
    path)."""

    lat_deg: float
    lon_deg: float
    alt_amsl_m: float

    def __init__(self, lat_deg: float, lon_deg: float, alt_amsl_m: float) -> None:
        self.lat_deg = lat_deg
        self.lon_deg = lon_deg
        self.alt_amsl_m = alt_amsl_m


@dataclass(frozen=True, slots=True)
class Vertex:
    lat_deg: float
    lon_deg: float
    global_frame: bool  # PX4 tests only global-frame vertices


@dataclass(frozen=True, slots=True)
class FenceArea:
    """One polygon (vertices) or circle (centre = vertices[0], radius); `loadable` False when the polygon runs past
    the end of the plan (PX4 cannot read its vertices)."""

    command: int
    vertices: tuple[Vertex, ...]
    radius_m: float = math.nan
    loadable: bool = True

    @property
    def inclusion(self) -> bool:
        return self.command in _INCLUSIONS

    @property
    def circle(self) -> bool:
        return self.command in _CIRCLES


@dataclass(frozen=True, slots=True)
class GeofenceSettings:
    action: int = GF_ACTION_HOLD  # GF_ACTION
    source: int = 0  # GF_SOURCE: 0 global position estimate, 1 GPS
    max_hor_dist_m: float = 0.0  # GF_MAX_HOR_DIST (0: off)
    max_ver_dist_m: float = 0.0  # GF_MAX_VER_DIST (0: off)


def distance_m(lat1: float, lon1: float, lat2: float, lon2: float) -> float:
    """get_distance_to_next_waypoint (lib/geo): the great-circle distance on PX4's sphere."""
    p1, p2 = math.radians(lat1), math.radians(lat2)
    d_lat, d_lon = p2 - p1, math.radians(lon2 - lon1)
    a = math.sin(d_lat / 2.0) ** 2 + math.sin(d_lon / 2.0) ** 2 * math.cos(p1) * math.cos(p2)
    return EARTH_RADIUS_M * 2.0 * math.atan2(math.sqrt(a), math.sqrt(max(0.0, 1.0 - a)))


def parse_areas(items: Sequence[MissionItem]) -> list[FenceArea]:
    """Every area of a stored fence plan in order (_updateFence's walk, before the home and position checks)."""
    areas: list[FenceArea] = []
    seq = 0
    while seq < len(items):
        item = items[seq]
        if item.command in _CIRCLES:
            areas.append(FenceArea(item.command, (_vertex(item),), radius_m=item.param1))
            seq += 1
        elif item.command in _POLYGONS:
            count = _vertex_count(item)
            if count == 0:  # PX4: "Polygon with 0 vertices. Skipping"
                seq += 1
                continue
            run = items[seq:seq + count]
            areas.append(FenceArea(item.command, tuple(_vertex(v) for v in run), loadable=len(run) == count))
            seq += count
        else:  # FENCE_RETURN_POINT (not used) or an unhandled command
            seq += 1
    return areas


def _vertex(item: MissionItem) -> Vertex:
    return Vertex(item.lat_deg, item.lon_deg, item.frame in GLOBAL_FRAMES)


def _vertex_count(item: MissionItem) -> int:
    """mission_fence_point.vertex_count: a uint16 from param1 (the upload refuses fewer than 3)."""
    p1 = item.param1
    return int(p1) & 0xFFFF if math.isfinite(p1) and p1 > 0 else 0


def inside_polygon(area: FenceArea, lat: float, lon: float) -> bool:
    """PNPOLY as Geofence::insidePolygon: crossings on raw degrees, edges (j, i) with j the previous vertex."""
    if not area.loadable:
        return False
    v = area.vertices
    inside = False
    j = len(v) - 1
    for i in range(len(v)):
        vi, vj = v[i], v[j]
        if not vi.global_frame:
            return inside
        if (vi.lon_deg >= lon) != (vj.lon_deg >= lon) and (
                lat <= (vj.lat_deg - vi.lat_deg) * (lon - vi.lon_deg) / (vj.lon_deg - vi.lon_deg) + vi.lat_deg):
            inside = not inside
        j = i
    return inside


@dataclass(slots=True)
class Geofence:
    """The fence PX4's navigator holds: the areas kept after the home/position checks, and the limits around home.
    `ref` is the circle test's projection reference, fixed at the first point tested (Geofence::insideCircle)."""

    areas: tuple[FenceArea, ...] = ()
    ref: GeoRef | None = field(default=None, compare=False)

    @property
    def empty(self) -> bool:
        return not self.areas

    def inside_circle(self, area: FenceArea, lat: float, lon: float) -> bool:
        centre = area.vertices[0]
        if not centre.global_frame:
            return False
        if self.ref is None:
            self.ref = GeoRef(lat, lon, 0.0)
        x1, y1, _ = global_to_ned(self.ref, lat, lon, 0.0)
        x2, y2, _ = global_to_ned(self.ref, centre.lat_deg, centre.lon_deg, 0.0)
        dx, dy = x1 - x2, y1 - y2
        return dx * dx + dy * dy < area.radius_m * area.radius_m

    def area_passes(self, area: FenceArea, lat: float, lon: float) -> bool:
        """checkPointAgainstPolygonCircle: inside an inclusion area, outside an exclusion area."""
        inside = self.inside_circle(area, lat, lon) if area.circle else inside_polygon(area, lat, lon)
        return inside if area.inclusion else not inside

    def inside_areas(self, lat: float, lon: float) -> bool:
        """isInsidePolygonOrCircle (no vertical bound for a MAVLink fence: see the module docstring)."""
        return all(self.area_passes(a, lat, lon) for a in self.areas)


def build_fence(items: Sequence[MissionItem], *, home: GeoPoint | None, position: GeoPoint | None,
                landed: bool, action: int) -> tuple[Geofence, list[str]]:
    """Geofence::_updateFence: the areas kept, and the CRITICAL texts for each one discarded."""
    fence = Geofence()
    kept: list[FenceArea] = []
    texts: list[str] = []
    for area in parse_areas(items):
        ok = True
        if home is not None and not fence.area_passes(area, home.lat_deg, home.lon_deg):
            texts.append(TEXT_NO_HOME)
            ok = False
        flying = action != GF_ACTION_NONE and not landed
        if flying and position is not None and not fence.area_passes(area, position.lat_deg, position.lon_deg):
            texts.append(TEXT_NO_CURRENT)
            ok = False
        if ok:
            kept.append(area)
    fence.areas = tuple(kept)
    return fence, texts


def closer_than_max_dist(s: GeofenceSettings, point: GeoPoint, home: GeoPoint | None) -> bool:
    """isCloserThanMaxDistToHome."""
    if s.max_hor_dist_m <= 1.1920929e-07 or home is None:
        return True
    return distance_m(point.lat_deg, point.lon_deg, home.lat_deg, home.lon_deg) < s.max_hor_dist_m


def below_max_alt(s: GeofenceSettings, alt_amsl_m: float, home: GeoPoint | None) -> bool:
    """isBelowMaxAltitude: the altitude above home's below GF_MAX_VER_DIST."""
    if s.max_ver_dist_m <= 1.1920929e-07 or home is None:
        return True
    return alt_amsl_m - home.alt_amsl_m < s.max_ver_dist_m


def point_allowed(fence: Geofence, s: GeofenceSettings, point: GeoPoint, home: GeoPoint | None) -> bool:
    """checkPointAgainstAllGeofences."""
    return (closer_than_max_dist(s, point, home) and below_max_alt(s, point.alt_amsl_m, home)
            and fence.inside_areas(point.lat_deg, point.lon_deg))


def home_required(s: GeofenceSettings) -> bool:
    """Geofence::isHomeRequired."""
    return s.max_hor_dist_m > 1.1920929e-07 or s.max_ver_dist_m > 1.1920929e-07 or s.action == GF_ACTION_RETURN


# mission_item_contains_position (navigator/mission_item_utils.h): waypoint, loiter unlimited / time, land, takeoff,
# loiter to altitude, VTOL takeoff / land
_POSITION_COMMANDS: Final = frozenset({
    MavCmd.NAV_WAYPOINT, MavCmd.NAV_LOITER_UNLIM, MavCmd.NAV_LOITER_TIME, MavCmd.NAV_LAND, MavCmd.NAV_TAKEOFF,
    MavCmd.NAV_LOITER_TO_ALT, MavCmd.NAV_VTOL_TAKEOFF, MavCmd.NAV_VTOL_LAND})


def mission_fence_violation(mission: Sequence[MissionItem], fence: Geofence, s: GeofenceSettings,
                            home: GeoPoint | None) -> str | None:
    """MissionFeasibilityChecker::checkMissionAgainstGeofence: None if the mission passes, else the CRITICAL text
    PX4 logs ("Geofence violation for waypoint N", N counting from 1; or the home requirement). The navigator runs
    it when a mission, fence or home changes; a failed check makes the mission invalid (MISSION_START denied)."""
    if home_required(s) and home is None:
        return "Geofence requires valid home position"
    for i, item in enumerate(mission):
        if item.frame in RELATIVE_FRAMES and home is None:
            return "Geofence requires valid home position"
        if item.command not in _POSITION_COMMANDS or item.frame not in GLOBAL_FRAMES:
            continue
        alt = item.z + home.alt_amsl_m if (item.frame in RELATIVE_FRAMES and home is not None) else item.z
        if not point_allowed(fence, s, GeoPoint(item.lat_deg, item.lon_deg, alt), home):
            return f"Geofence violation for waypoint {i + 1}"
    return None


@dataclass(slots=True)
class GeofenceResult:
    """geofence_result (navigator -> commander): which limit is crossed, and GF_ACTION; read-only by convention (made
    at every geofence check: ARCHITECTURE.md, On the tick path)."""

    max_dist: bool = False
    max_alt: bool = False
    custom: bool = False
    action: int = GF_ACTION_NONE

    def __init__(self, max_dist: bool = False, max_alt: bool = False, custom: bool = False,
                 action: int = GF_ACTION_NONE) -> None:
        self.max_dist = max_dist
        self.max_alt = max_alt
        self.custom = custom
        self.action = action

    def __eq__(self, other: object) -> bool:
        """The dataclass's comparison, written out so that mypyc compiles it (the commander's checks compare results
        every cycle)."""
        if not isinstance(other, GeofenceResult):
            return NotImplemented
        return (self.max_dist == other.max_dist and self.max_alt == other.max_alt and self.custom == other.custom
                and self.action == other.action)

    @property
    def triggered(self) -> bool:
        return self.max_dist or self.max_alt or self.custom

    @property
    def breached(self) -> bool:
        """failsafe_flags.geofence_breached (commander geofenceCheck.cpp): a limit crossed and GF_ACTION not None;
        it also fails the arming checks in every mode."""
        return self.triggered and self.action != GF_ACTION_NONE

    def health_texts(self) -> list[str]:
        """The legacy CRITICAL texts geofenceCheck.cpp logs when the health report changes."""
        if not self.breached:
            return []
        texts = []
        if self.max_dist:
            texts.append("Geofence: exceeding maximum distance to Home")
        if self.max_alt:
            texts.append("Geofence: exceeding maximum altitude above Home")
        if self.custom:
            texts.append("Geofence: approaching or outside geofence")
        return texts


NO_BREACH: Final = GeofenceResult()
