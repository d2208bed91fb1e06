"""Where Return goes: home or a rally (safe) point, as RTL_TYPE says. Pure (no MAVLink, no clock).

After src/modules/navigator/rtl.cpp (setRtlTypeAndDestination, findRtlDestination, findClosestSafePoint, PX4 main
2026-08) and mission_route_types.cpp (extractSafePointPosition):
- a rally point is a NAV_RALLY_POINT item of the rally plan in a global frame: its altitude AMSL (GLOBAL) or above
  home (GLOBAL_RELATIVE_ALT); others are skipped;
- RTL_TYPE 0: the closest of home and the rally points more than 10 m from home; 1: the closest rally point more
  than 10 m from home, home if there is none; 3: as 0; 5: the closest rally point (wherever it is), else the current
  position (with home's yaw); 2 and 4 (mission paths) return home when no valid mission is stored (the mission
  flown back: flight_tasks/rtl_mission.py);
- a candidate replaces the best so far only if it is closer by more than 2 m (MIN_DIST_THRESHOLD); distances are
  great circles from the current position;
- a rally point has no yaw (NaN: the vehicle keeps or turns to its course), home has home's yaw.
Not modelled: the mission landing of RTL_TYPE 1 and 3 (DO_LAND_START), VTOL approaches.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Final

from sitl_emu.navigator.geofence import GeoPoint, distance_m
from sitl_emu.navigator.mission_store import MissionItem
from sitl_emu.px4 import ABSOLUTE_FRAMES, RELATIVE_FRAMES, MavCmd

MIN_DIST_THRESHOLD_M: Final = 2.0
NEAR_HOME_M: Final = 10.0  # mission_route::kLandApproachAssociationDistanceM
RTL_TYPE_HOME_FIRST, RTL_TYPE_SAFE_FIRST, RTL_TYPE_SAFE_ONLY = 0, 1, 5


@dataclass(frozen=True, slots=True)
class RtlDestination:
    point: GeoPoint
    yaw_rad: float
    safe_point_index: int | None = None  # rtl_status.safe_point_index; None: home (or current position)


def safe_points(items: Sequence[MissionItem], home_alt_amsl_m: float) -> list[tuple[int, GeoPoint]]:
    """(index in the rally plan, position) of every usable rally point."""
    points = []
    for index, item in enumerate(items):
        if item.command != MavCmd.NAV_RALLY_POINT:
            continue
        if item.frame in ABSOLUTE_FRAMES:
            alt = item.z
        elif item.frame in RELATIVE_FRAMES and math.isfinite(home_alt_amsl_m):
            alt = item.z + home_alt_amsl_m
        else:
            continue
        points.append((index, GeoPoint(item.lat_deg, item.lon_deg, alt)))
    return points


def choose_destination(rtl_type: int, rally: Sequence[MissionItem], home: GeoPoint, home_yaw_rad: float,
                       position: GeoPoint) -> RtlDestination:
    """RTL::findRtlDestination for a multicopter."""
    best = RtlDestination(home, home_yaw_rad)
    if rtl_type not in (0, 1, 3, RTL_TYPE_SAFE_ONLY):
        return best
    min_dist = math.inf
    if rtl_type == RTL_TYPE_HOME_FIRST or rtl_type == 3:
        min_dist = distance_m(position.lat_deg, position.lon_deg, home.lat_deg, home.lon_deg)
    for index, point in safe_points(rally, home.alt_amsl_m):
        far_from_home = distance_m(home.lat_deg, home.lon_deg, point.lat_deg, point.lon_deg) > NEAR_HOME_M
        if not (far_from_home or rtl_type == RTL_TYPE_SAFE_ONLY):
            continue
        dist = distance_m(position.lat_deg, position.lon_deg, point.lat_deg, point.lon_deg)
        if dist + MIN_DIST_THRESHOLD_M < min_dist:
            min_dist = dist
            best = RtlDestination(point, math.nan, index)
    if best.safe_point_index is None and rtl_type == RTL_TYPE_SAFE_ONLY:
        return RtlDestination(position, home_yaw_rad)  # only lat/lon/alt replaced: home's yaw stays
    return best
