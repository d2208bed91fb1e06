"""Which params of an uploaded mission item PX4 main uses, and its refusal of a value in any other.

After src/modules/mavlink/mavlink_command_params.hpp (PX4 main since mid-2026, PRs 27541 and 28079), which
parse_mavlink_mission_item consults before it reads an item: each MAV_CMD it knows lists the params (1-7) a mission
item of it carries; a param outside that list must be "unset", else the upload ends with
MAV_MISSION_INVALID_PARAM<n> for the first such param. Commands missing from the list are not checked here (the
parser refuses them later as MAV_MISSION_UNSUPPORTED if it does not know them either).

"Unset" is NaN or 0 for a float param (0 being what ground stations send by default). x and y (params 5 and 6) of
a MISSION_ITEM_INT in a global frame are latitude and longitude as int32, where only INT32_MAX and INT32_MIN (a NaN
converted to int32) mean unset, so 0 is a value: an RTL item in a global frame at x = y = 0 is refused with
MAV_MISSION_INVALID_PARAM5_X (../shared/reference/px4-mission/cases.json `bad.rtl_global_frame_zero_xy`), while a
fence circle at lat 0, lon 0 is accepted (a fence circle uses x and y; px4-recorded-facts.md section 4), and so is
QGroundControl's RTL item in MAV_FRAME_MISSION with x = y = 0 (`upload.valid`), where the check reads x and y as
numbers and 0 is unset again.
"""

from __future__ import annotations

import math
from typing import Final

from sitl_emu.px4 import MavCmd

INT32_MAX: Final = 2**31 - 1
INT32_MIN: Final = -(2**31)
MAV_MISSION_INVALID_PARAM1: Final = 6  # PARAM2..4 = 7..9, PARAM5_X = 10, PARAM6_Y = 11, PARAM7 = 12 (common.xml)

_POSITION = (5, 6, 7)  # latitude, longitude, altitude
# params a multicopter's mission item of each command may carry (the table's mission column, with its
# multicopter override: NAV_TAKEOFF's param1, which QGroundControl sends as -1)
USED_PARAMS: Final[dict[int, tuple[int, ...]]] = {
    MavCmd.NAV_WAYPOINT: (1, 2, 4, *_POSITION),
    MavCmd.NAV_LOITER_UNLIM: (3, 4, *_POSITION),
    MavCmd.NAV_LOITER_TIME: (1, 2, 3, 4, *_POSITION),
    MavCmd.NAV_RETURN_TO_LAUNCH: (),
    MavCmd.NAV_LAND: (1, 2, 4, *_POSITION),
    MavCmd.NAV_TAKEOFF: (1, 4, *_POSITION),
    MavCmd.NAV_LOITER_TO_ALT: (1, 2, 4, *_POSITION),
    MavCmd.NAV_ROI: (1, 2, 3, *_POSITION),
    MavCmd.NAV_VTOL_TAKEOFF: (4, *_POSITION),
    MavCmd.NAV_VTOL_LAND: (4, *_POSITION),
    MavCmd.NAV_DELAY: (1, 2, 3, 4),
    MavCmd.CONDITION_DELAY: (1,),
    MavCmd.CONDITION_DISTANCE: (1,),
    MavCmd.DO_SET_MODE: (1, 2, 3),
    MavCmd.DO_JUMP: (1, 2),
    MavCmd.DO_CHANGE_SPEED: (1, 2, 3),
    MavCmd.DO_SET_HOME: (1, 2, 3, 4, *_POSITION),
    MavCmd.DO_LAND_START: (),
    MavCmd.DO_SET_ROI_LOCATION: _POSITION,
    MavCmd.DO_SET_ROI_WPNEXT_OFFSET: (1,),
    MavCmd.DO_SET_ROI_NONE: (1,),
    MavCmd.DO_SET_ROI: (1, 2, 3),
    MavCmd.DO_SET_CAM_TRIGG_DIST: (1, 2, 3, 4),
    MavCmd.DO_GRIPPER: (1, 2),
    MavCmd.DO_AUTOTUNE_ENABLE: (1, 2),
    MavCmd.DO_SET_CAM_TRIGG_INTERVAL: (1, 2, 3),
    MavCmd.COMPONENT_ARM_DISARM: (1, 2),
    MavCmd.INJECT_FAILURE: (1, 2, 3),
    MavCmd.SET_CAMERA_MODE: (1, 2),
    MavCmd.SET_CAMERA_FOCUS: (1, 2, 3),
    MavCmd.SET_CAMERA_SOURCE: (1, 2, 3),
    MavCmd.IMAGE_START_CAPTURE: (1, 2, 3, 4),
    MavCmd.IMAGE_STOP_CAPTURE: (1,),
    MavCmd.DO_TRIGGER_CONTROL: (1, 2, 3, 4),
    MavCmd.VIDEO_START_CAPTURE: (1, 2, 3),
    MavCmd.VIDEO_STOP_CAPTURE: (1, 2),
    MavCmd.DO_VTOL_TRANSITION: (1, 2),
    MavCmd.CONDITION_GATE: (),
    MavCmd.NAV_FENCE_RETURN_POINT: _POSITION,
    MavCmd.NAV_FENCE_POLYGON_VERTEX_INCLUSION: (1, 5, 6),
    MavCmd.NAV_FENCE_POLYGON_VERTEX_EXCLUSION: (1, 5, 6),
    MavCmd.NAV_FENCE_CIRCLE_INCLUSION: (1, 5, 6),
    MavCmd.NAV_FENCE_CIRCLE_EXCLUSION: (1, 5, 6),
    MavCmd.NAV_RALLY_POINT: _POSITION,
    MavCmd.DO_WINCH: (1, 2, 3, 4),
}


def unused_param_result(command: int, params: tuple[float, ...], x: float, y: float, z: float,
                        int_position: bool) -> int | None:
    """MAV_MISSION_INVALID_PARAM<n> for the first param the item carries where `command` uses none, else None.

    `params` are param1..4; `x`, `y` as the message carries them; `int_position`: they are a MISSION_ITEM_INT's
    int32 latitude and longitude (a global frame), where only INT32_MAX / INT32_MIN mean unset.
    """
    used = USED_PARAMS.get(command)
    if used is None:
        return None
    carried = [not _float_unset(p) for p in params]
    carried += [not _position_unset(x, int_position), not _position_unset(y, int_position), not _float_unset(z)]
    bad = next((n for n, value_given in enumerate(carried, start=1) if value_given and n not in used), None)
    return None if bad is None else MAV_MISSION_INVALID_PARAM1 + bad - 1


def _float_unset(value: float) -> bool:
    return math.isnan(value) or value == 0.0


def _position_unset(value: float, int_position: bool) -> bool:
    """x or y unset: only the int32 sentinels for a global MISSION_ITEM_INT; else also NaN or 0 (a
    MISSION_ITEM_INT in MAV_FRAME_MISSION may carry the sentinels too, PR 28079)."""
    return value in (INT32_MAX, INT32_MIN) or (not int_position and _float_unset(value))
