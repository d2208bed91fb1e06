"""Where Return goes: home or a rally (safe) point, as RTL_TYPE says. Pure (no MAVLink, no clock).

After src/modules/navigator/rtl.cpp (setRtlTypeAndDestination, findRtlDestination, findClosestSafePoint, PX4 main
2026-08) and mission_route_types.cpp (extractSafePointPosition):
- a rally point is a NAV_RALLY_POINT item of the rally plan in a global frame: its altitude AMSL (GLOBAL) or above
  home (GLOBAL_RELATIVE_ALT); others are skipped;
- RTL_TYPE 0: the closest of home and the rally points more than 10 m from home; 1: the closest of the mission's
  landing and the rally points more than 10 m from home, home if there is neither; 3: the closest of home, the
  mission's landing and those rally points; 5: the closest rally point (wherever it is), else the current position
  (with home's yaw); 2 and 4 (mission paths) return home when no valid mission is stored (the mission flown back:
  flight_tasks/rtl_mission.py);
- the mission's landing (a valid mission with a land item, mission.land_start_index / land_index) is the land
  item's position; chosen, Return flies the mission's landing (RtlDirectMissionLand, flight_tasks/rtl_mission.py);
- a candidate replaces the best so far only if it is closer by more than 2 m (MIN_DIST_THRESHOLD); distances are
  great circles from the current position;
- a rally point has no yaw (NaN: the vehicle keeps or turns to its course), home and the mission landing have home's
  yaw (setLandPosAsDestination replaces only the position).
Not modelled: VTOL approaches.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Final, NamedTuple

from sitl_emu.navigator.geofence import GeoPoint, distance_m
from sitl_emu.navigator.mission_store import MissionItem
from sitl_emu.px4 import ABSOLUTE_FRAMES, RELATIVE_FRAMES, MavCmd
from sitl_emu.types import Vec3

MIN_DIST_THRESHOLD_M: Final = 2.0
NEAR_HOME_M: Final = 10.0  # mission_route::kLandApproachAssociationDistanceM
RTL_TYPE_HOME_FIRST, RTL_TYPE_SAFE_FIRST, RTL_TYPE_CLOSEST, RTL_TYPE_SAFE_ONLY = 0, 1, 3, 5


@dataclass(frozen=True, slots=True)
class RtlDestination:
    point: GeoPoint
    yaw_rad: float
    safe_point_index: int | None = None  # rtl_status.safe_point_index; None: home (or current position)
    mission_land: bool = False  # DESTINATION_TYPE_MISSION_LAND: the mission's landing


class ReturnDestination(NamedTuple):
    """Where Return goes in the local frame: a rally point or the mission's landing (`mission_land`)."""

    pos_ned_m: Vec3
    yaw_rad: float
    mission_land: bool = False


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


def land_markers(items: Sequence[MissionItem]) -> tuple[int, int]:
    """(land_start_index, land_index) as mavlink_mission.cpp marks them on upload: the first DO_LAND_START, the first
    land item; with no DO_LAND_START before it, the land item starts the landing too. -1: none."""
    land_start = land = -1
    for index, item in enumerate(items):
        if item.command == MavCmd.DO_LAND_START and land_start < 0:
            land_start = index
        if item.command in (MavCmd.NAV_LAND, MavCmd.NAV_VTOL_LAND) and land < 0:
            land = index
            land_start = land if land_start < 0 else land_start
    return land_start, land


def mission_landing(items: Sequence[MissionItem], mission_valid: bool, home_alt_amsl_m: float) -> GeoPoint | None:
    """The mission's landing RTL may choose (RTL::hasMissionLandStart, setLandPosAsDestination): the land item's
    position, its altitude AMSL; None without a valid mission with both markers."""
    land_start, land = land_markers(items)
    if not mission_valid or land_start < 0 or land < 0:
        return None
    item = items[land]
    alt = item.z + home_alt_amsl_m if item.frame in RELATIVE_FRAMES else item.z
    return GeoPoint(item.lat_deg, item.lon_deg, alt)


def choose_destination(rtl_type: int, rally: Sequence[MissionItem], home: GeoPoint, home_yaw_rad: float,
                       position: GeoPoint, mission_land: GeoPoint | None = None) -> RtlDestination:
    """RTL::findRtlDestination for a multicopter; `mission_land`: the mission's land item (None: no landing)."""
    best = RtlDestination(home, home_yaw_rad)
    if rtl_type not in (0, 1, 3, RTL_TYPE_SAFE_ONLY):
        return best
    min_dist = math.inf
    if rtl_type in (RTL_TYPE_HOME_FIRST, RTL_TYPE_CLOSEST):
        min_dist = distance_m(position.lat_deg, position.lon_deg, home.lat_deg, home.lon_deg)
    if rtl_type in (RTL_TYPE_SAFE_FIRST, RTL_TYPE_CLOSEST) and mission_land is not None:
        dist = distance_m(position.lat_deg, position.lon_deg, mission_land.lat_deg, mission_land.lon_deg)
        if dist + MIN_DIST_THRESHOLD_M < min_dist:
            min_dist = dist
            best = RtlDestination(mission_land, home_yaw_rad, None, True)
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
