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

from sitl_emu.geo import GeoRef, global_to_ned
from sitl_emu.navigator.mission_store import MissionItem
from sitl_emu.px4 import RELATIVE_FRAMES, MavCmd
from sitl_emu.types import NAN, Vec3

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


# what the navigator does with each command it acts on; any other is an action
_KINDS: Final[dict[int, Kind]] = {
    MavCmd.NAV_WAYPOINT: Kind.WAYPOINT, MavCmd.NAV_LOITER_TO_ALT: Kind.WAYPOINT, MavCmd.NAV_TAKEOFF: Kind.TAKEOFF,
    MavCmd.NAV_LAND: Kind.LAND, MavCmd.NAV_LOITER_TIME: Kind.LOITER_TIME, MavCmd.NAV_LOITER_UNLIM: Kind.LOITER_UNLIM,
    MavCmd.NAV_DELAY: Kind.DELAY, MavCmd.NAV_RETURN_TO_LAUNCH: Kind.RTL, MavCmd.DO_JUMP: Kind.JUMP,
}
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
    if kind in POSITION_KINDS or item.command == MavCmd.DO_SET_ROI_LOCATION:
        alt_amsl = item.z + home_alt_amsl_m if item.frame in RELATIVE_FRAMES else item.z
        target = global_to_ned(ref, item.lat_deg, item.lon_deg, alt_amsl)
        rel = alt_amsl - home_alt_amsl_m
    holds = kind in (Kind.WAYPOINT, Kind.LOITER_TIME, Kind.DELAY) and item.command != MavCmd.NAV_LOITER_TO_ALT
    hold = item.param1 if holds else 0.0
    acceptance = item.param2 if kind is Kind.WAYPOINT else NAN
    yaw = math.radians(item.param4) if kind in (Kind.WAYPOINT, Kind.LOITER_TIME, Kind.LOITER_UNLIM) else NAN
    if math.isfinite(yaw):
        yaw = (yaw + math.pi) % math.tau - math.pi
    return NavItem(seq=item.seq, command=item.command, kind=kind, target_ned_m=target, relative_alt_m=rel,
                   hold_s=max(hold, 0.0) if math.isfinite(hold) else 0.0, acceptance_m=acceptance, yaw_rad=yaw,
                   autocontinue=bool(item.autocontinue), params=params)


def nav_items(items: tuple[MissionItem, ...], ref: GeoRef, home_alt_amsl_m: float) -> tuple[NavItem, ...]:
    return tuple(nav_item(it, ref, home_alt_amsl_m) for it in items)
