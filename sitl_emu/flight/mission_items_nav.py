"""Stored mission items as the navigator flies them: local NED targets, hold times, acceptance radii.

PX4's mavlink_mission.cpp (parse_mavlink_mission_item) turns each MISSION_ITEM into a mission_item_s (nav_cmd,
lat/lon, altitude and whether it is relative to home, time_inside, acceptance_radius, yaw); the navigator
(src/modules/navigator/mission_block.cpp get_absolute_altitude_for_item) adds home's altitude to relative altitudes.
Here the same, into the local frame: z = -(altitude AMSL - the local origin's altitude). No MAVLink.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum
from typing import Final

from sitl_emu.flight.mission_store import MissionItem
from sitl_emu.geo import GeoRef, global_to_ned
from sitl_emu.types import NAN, Vec3

# MAV_CMD numbers the navigator acts on (common.xml)
WAYPOINT, LOITER_UNLIM, LOITER_TIME, RTL, LAND, TAKEOFF, LOITER_TO_ALT = 16, 17, 19, 20, 21, 22, 31
DELAY, DO_JUMP, DO_CHANGE_SPEED, DO_SET_ROI_LOCATION, DO_SET_ROI_NONE, DO_SET_ROI = 93, 177, 178, 195, 197, 201
FRAME_GLOBAL, FRAME_GLOBAL_REL, FRAME_GLOBAL_INT, FRAME_GLOBAL_REL_INT = 0, 3, 5, 6
_RELATIVE_FRAMES: Final = (FRAME_GLOBAL_REL, FRAME_GLOBAL_REL_INT)
_ABSOLUTE_FRAMES: Final = (FRAME_GLOBAL, FRAME_GLOBAL_INT)
MAV_ROI_NONE, MAV_ROI_LOCATION = 0, 3


class Kind(Enum):
    """What the navigator does with an item (mission_block.cpp is_mission_item_reached_or_completed)."""

    WAYPOINT = "waypoint"  # fly there (also LOITER_TO_ALT)
    TAKEOFF = "takeoff"
    LAND = "land"  # reached when landed
    LOITER_TIME = "loiter_time"
    LOITER_UNLIM = "loiter_unlim"  # never reached
    DELAY = "delay"  # hold where the vehicle is for param1 seconds
    RTL = "rtl"  # the navigator asks the commander for Return; completes at once
    JUMP = "jump"  # resolved when the item is loaded, never flown
    ACTION = "action"  # DO_* and the rest: complete at once


_KINDS: Final = {WAYPOINT: Kind.WAYPOINT, LOITER_TO_ALT: Kind.WAYPOINT, TAKEOFF: Kind.TAKEOFF, LAND: Kind.LAND,
                 LOITER_TIME: Kind.LOITER_TIME, LOITER_UNLIM: Kind.LOITER_UNLIM, DELAY: Kind.DELAY, RTL: Kind.RTL,
                 DO_JUMP: Kind.JUMP}
POSITION_KINDS: Final = frozenset({Kind.WAYPOINT, Kind.TAKEOFF, Kind.LAND, Kind.LOITER_TIME, Kind.LOITER_UNLIM})


@dataclass(frozen=True, slots=True)
class NavItem:
    """One item in the navigator's terms. `target_ned_m` is NaN for items without a position."""

    seq: int
    command: int
    kind: Kind
    target_ned_m: Vec3
    relative_alt_m: float  # the item's altitude above home (NaN without a position)
    hold_s: float  # mission_item.time_inside: WAYPOINT / LOITER_TIME / DELAY param1
    acceptance_m: float  # the item's acceptance radius (NaN or <= 0: NAV_ACC_RAD)
    yaw_rad: float  # NaN: FlightTaskAuto chooses the heading
    autocontinue: bool
    params: tuple[float, float, float, float]

    @property
    def has_position(self) -> bool:
        return self.kind in POSITION_KINDS


def nav_item(item: MissionItem, ref: GeoRef, home_alt_amsl_m: float) -> NavItem:
    """The navigator's view of a stored item; relative altitudes are above `home_alt_amsl_m`."""
    kind = _KINDS.get(item.command, Kind.ACTION)
    params = (item.param1, item.param2, item.param3, item.param4)
    target: Vec3 = (NAN, NAN, NAN)
    rel = NAN
    if kind in POSITION_KINDS or item.command == DO_SET_ROI_LOCATION:
        alt_amsl = item.z + home_alt_amsl_m if item.frame in _RELATIVE_FRAMES else item.z
        target = global_to_ned(ref, item.lat_deg, item.lon_deg, alt_amsl)
        rel = alt_amsl - home_alt_amsl_m
    hold = item.param1 if kind in (Kind.WAYPOINT, Kind.LOITER_TIME, Kind.DELAY) and item.command != LOITER_TO_ALT \
        else 0.0
    acceptance = item.param2 if kind is Kind.WAYPOINT else NAN
    yaw = math.radians(item.param4) if kind in (Kind.WAYPOINT, Kind.LOITER_TIME, Kind.LOITER_UNLIM) else NAN
    if math.isfinite(yaw):
        yaw = (yaw + math.pi) % math.tau - math.pi
    return NavItem(item.seq, item.command, kind, target, rel, max(hold, 0.0) if math.isfinite(hold) else 0.0,
                   acceptance, yaw, bool(item.autocontinue), params)


def nav_items(items: tuple[MissionItem, ...], ref: GeoRef, home_alt_amsl_m: float) -> tuple[NavItem, ...]:
    return tuple(nav_item(it, ref, home_alt_amsl_m) for it in items)
