"""Which params of a command or a mission item PX4 main uses, and its refusal of a value in any other.

After src/modules/mavlink/mavlink_command_params.hpp (PX4 main since mid-2026, PRs 27541 and 28079): for each MAV_CMD
it knows, PX4 lists the params (1-7) a mission item of it may carry and, separately, the params a COMMAND_LONG or
COMMAND_INT of it may carry. A param outside the list must be "unset", else:
- a mission upload ends with MAV_MISSION_INVALID_PARAM<n> for the first such param (mavlink_mission.cpp,
  parse_mavlink_mission_item);
- a command is answered DENIED at the MAVLink boundary, before any module sees it (mavlink_receiver.cpp; reference
  px4-behaviour.md 3.1: e.g. NAV_RETURN_TO_LAUNCH with any param, DO_SET_MODE with params 4-7, ARM_DISARM with 3-7,
  NAV_TAKEOFF with 2 or 3 on a multicopter).
Commands missing from the table are not checked.

"Unset" is NaN or 0 for a float param (0 being what ground stations send by default). x and y (params 5 and 6) of
a MISSION_ITEM_INT in a global frame are latitude and longitude as int32, where only INT32_MAX and INT32_MIN (a NaN
converted to int32) mean unset, so 0 is a value: an RTL item in a global frame at x = y = 0 is refused with
MAV_MISSION_INVALID_PARAM5_X (../shared/reference/px4-mission/cases.json `bad.rtl_global_frame_zero_xy`), while a
fence circle at lat 0, lon 0 is accepted (a fence circle uses x and y; px4-recorded-facts.md section 4), and so is
QGroundControl's RTL item in MAV_FRAME_MISSION with x = y = 0 (`upload.valid`), where the check reads x and y as
numbers and 0 is unset again. A command's params 5 and 6 are checked as the floats the receiver makes of them.
"""

from __future__ import annotations

import math
from typing import Final, NamedTuple

from sitl_emu.px4 import MavCmd

INT32_MAX: Final = 2**31 - 1
INT32_MIN: Final = -(2**31)
MAV_MISSION_INVALID_PARAM1: Final = 6  # PARAM2..4 = 7..9, PARAM5_X = 10, PARAM6_Y = 11, PARAM7 = 12 (common.xml)
DO_SET_GLOBAL_ORIGIN: Final = 611  # newer than pymavlink's common.xml, hence not in MavCmd


class UsedParams(NamedTuple):
    """The params (numbered 1-7) PX4 takes from a mission item and from a command of one MAV_CMD."""

    mission: tuple[int, ...]
    command: tuple[int, ...]


_POS: Final = (5, 6, 7)  # latitude, longitude, altitude


def _same(*used: int) -> UsedParams:
    return UsedParams(used, used)


# The table for a multicopter, with its one vehicle override folded in: NAV_TAKEOFF's param1 (the fixed-wing pitch,
# which QGroundControl sends as -1 to a multicopter too).
USED_PARAMS: Final[dict[int, UsedParams]] = {
    MavCmd.NAV_WAYPOINT: _same(1, 2, 4, *_POS),
    MavCmd.NAV_LOITER_UNLIM: _same(3, 4, *_POS),
    MavCmd.NAV_LOITER_TIME: _same(1, 2, 3, 4, *_POS),
    MavCmd.NAV_RETURN_TO_LAUNCH: _same(),
    MavCmd.NAV_LAND: _same(1, 2, 4, *_POS),
    MavCmd.NAV_TAKEOFF: _same(1, 4, *_POS),
    MavCmd.NAV_LOITER_TO_ALT: _same(1, 2, 4, *_POS),
    MavCmd.NAV_ROI: _same(1, 2, 3, *_POS),
    MavCmd.NAV_VTOL_TAKEOFF: UsedParams((4, *_POS), (3, 4, *_POS)),
    MavCmd.NAV_VTOL_LAND: UsedParams((3, 4, *_POS), (1, 2, 3, 4, *_POS)),
    MavCmd.NAV_DELAY: _same(1, 2, 3, 4),
    MavCmd.CONDITION_DELAY: _same(1),
    MavCmd.CONDITION_DISTANCE: _same(1),
    MavCmd.DO_SET_MODE: _same(1, 2, 3),
    MavCmd.DO_JUMP: _same(1, 2),
    MavCmd.DO_CHANGE_SPEED: _same(1, 2, 3),
    MavCmd.DO_SET_HOME: _same(1, 2, 3, 4, *_POS),
    MavCmd.DO_LAND_START: _same(*_POS),  # an optional marker position, which QGroundControl sets
    MavCmd.DO_SET_ROI_LOCATION: UsedParams(_POS, (1, *_POS)),
    MavCmd.DO_SET_ROI_WPNEXT_OFFSET: _same(1),
    MavCmd.DO_SET_ROI_NONE: _same(1),
    MavCmd.DO_SET_ROI: _same(1, 2, 3),
    MavCmd.DO_SET_CAM_TRIGG_DIST: _same(1, 2, 3, 4),
    MavCmd.DO_GRIPPER: _same(1, 2),
    MavCmd.DO_AUTOTUNE_ENABLE: _same(1, 2),
    MavCmd.DO_SET_CAM_TRIGG_INTERVAL: _same(1, 2, 3),
    MavCmd.DO_SET_MISSION_CURRENT: UsedParams((), (1, 2)),
    MavCmd.COMPONENT_ARM_DISARM: _same(1, 2),
    MavCmd.INJECT_FAILURE: _same(1, 2, 3, 4),
    MavCmd.SET_CAMERA_MODE: _same(1, 2),
    MavCmd.SET_CAMERA_FOCUS: _same(1, 2, 3),
    MavCmd.SET_CAMERA_SOURCE: _same(1, 2, 3),
    DO_SET_GLOBAL_ORIGIN: UsedParams((), _POS),
    MavCmd.IMAGE_START_CAPTURE: _same(1, 2, 3, 4),
    MavCmd.IMAGE_STOP_CAPTURE: _same(1),
    MavCmd.DO_TRIGGER_CONTROL: _same(1, 2, 3, 4),
    MavCmd.VIDEO_START_CAPTURE: _same(1, 2, 3),
    MavCmd.VIDEO_STOP_CAPTURE: _same(1, 2),
    MavCmd.DO_VTOL_TRANSITION: _same(1, 2),
    MavCmd.CONDITION_GATE: UsedParams((1, 2, *_POS), ()),
    MavCmd.NAV_FENCE_RETURN_POINT: UsedParams(_POS, ()),
    MavCmd.NAV_FENCE_POLYGON_VERTEX_INCLUSION: UsedParams((1, 5, 6), (1,)),
    MavCmd.NAV_FENCE_POLYGON_VERTEX_EXCLUSION: UsedParams((1, 5, 6), (1,)),
    MavCmd.NAV_FENCE_CIRCLE_INCLUSION: UsedParams((1, 5, 6), (1,)),
    MavCmd.NAV_FENCE_CIRCLE_EXCLUSION: UsedParams((1, 5, 6), (1,)),
    MavCmd.NAV_RALLY_POINT: UsedParams(_POS, ()),
    MavCmd.DO_WINCH: _same(1, 2, 3, 4),
}


def unused_param_result(command: int, params: tuple[float, ...], x: float, y: float, z: float,
                        int_position: bool) -> int | None:
    """MAV_MISSION_INVALID_PARAM<n> for the first param a mission item carries where `command` uses none, else None.

    `params` are param1..4; `x`, `y` as the message carries them; `int_position`: they are a MISSION_ITEM_INT's
    int32 latitude and longitude (a global frame), where only INT32_MAX / INT32_MIN mean unset.
    """
    used = USED_PARAMS.get(command)
    if used is None:
        return None
    carried = [not _float_unset(p) for p in params]
    carried += [not _position_unset(x, int_position), not _position_unset(y, int_position), not _float_unset(z)]
    bad = _first_unused(carried, used.mission)
    return None if bad is None else MAV_MISSION_INVALID_PARAM1 + bad - 1


def command_carries_unused_param(command: int, params: tuple[float, ...]) -> bool:
    """True when a COMMAND_LONG / COMMAND_INT (its seven params as floats) sets a param its command does not use."""
    used = USED_PARAMS.get(command)
    return used is not None and _first_unused([not _float_unset(p) for p in params], used.command) is not None


def _first_unused(carried: list[bool], used: tuple[int, ...]) -> int | None:
    return next((n for n, value_given in enumerate(carried, start=1) if value_given and n not in used), None)


def _float_unset(value: float) -> bool:
    return math.isnan(value) or value == 0.0


def _position_unset(value: float, int_position: bool) -> bool:
    """x or y unset: only the int32 sentinels for a global MISSION_ITEM_INT; else also NaN or 0 (a
    MISSION_ITEM_INT in MAV_FRAME_MISSION may carry the sentinels too, PR 28079)."""
    return value in (INT32_MAX, INT32_MIN) or (not int_position and _float_unset(value))
