"""Mission items on the wire: PX4's checks on an uploaded item, and the item PX4 sends back on a download.

After src/modules/mavlink/mavlink_mission.cpp (parse_mavlink_mission_item, format_mavlink_mission_item): an item is
either positional (a global frame: lat/lon/alt) or a "mission frame" command (MAV_FRAME_MISSION: seven raw params);
any other frame (local, body, terrain) is refused with MAV_MISSION_UNSUPPORTED_FRAME, a command PX4 does not know in
that frame with MAV_MISSION_UNSUPPORTED. PX4 keeps its own parsed item, not the message, so a download returns what it
kept: the altitude reference as the INT or float variant of the global frame, and only the params the command uses
(e.g. a waypoint's pass radius comes back as 0, its yaw wrapped into [0, 360)).

Before any of that PX4 main refuses a value in a param the command does not use (command_params.py): e.g. an RTL
item in a global frame at x = y = 0 is MAV_MISSION_INVALID_PARAM5_X, a waypoint's pass radius (param3)
MAV_MISSION_INVALID_PARAM3.

DO_LAND_START is a marker in either frame: in MAV_FRAME_MISSION (QGroundControl's landing patterns,
LandingComplexItem: all seven params 0) it is kept as sent; in a global frame (a plain DO_LAND_START item placed on
QGroundControl's map carries the optional position MAVLink gives it, params 5-7, which PX4 main's parameter table
allows) PX4 keeps the position and no param, and a download returns it in the global frame. Either way the navigator
flies nothing there: the landing starts at the next position item (mission.land_start_index, RTL's mission landing).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from sitl_emu.mavlink.protocols.command_params import unused_param_result
from sitl_emu.navigator.mission_store import PLAN_FENCE, PLAN_MISSION, MissionItem, MissionStore
from sitl_emu.px4 import MavCmd, MavFrame, NavState

if TYPE_CHECKING:
    from sitl_emu.mavlink.wire.encoding import MessageEncoder
    from sitl_emu.mavlink.wire.fastpack import Packed

# MAV_MISSION_RESULT (common.xml)
MAV_MISSION_ACCEPTED = 0
MAV_MISSION_ERROR = 1
MAV_MISSION_UNSUPPORTED_FRAME = 2
MAV_MISSION_UNSUPPORTED = 3
MAV_MISSION_NO_SPACE = 4
MAV_MISSION_INVALID = 5
MAV_MISSION_INVALID_PARAM1 = 6
MAV_MISSION_INVALID_PARAM5_X = 10
MAV_MISSION_OPERATION_CANCELLED = 15

# PX4 keeps a global item's altitude reference, which the INT and float variants of a frame share
_INT_FRAMES: dict[int, MavFrame] = {
    MavFrame.GLOBAL: MavFrame.GLOBAL_INT, MavFrame.GLOBAL_RELATIVE_ALT: MavFrame.GLOBAL_RELATIVE_ALT_INT,
    MavFrame.GLOBAL_INT: MavFrame.GLOBAL_INT, MavFrame.GLOBAL_RELATIVE_ALT_INT: MavFrame.GLOBAL_RELATIVE_ALT_INT}
_FLOAT_FRAMES: dict[int, MavFrame] = {
    MavFrame.GLOBAL_INT: MavFrame.GLOBAL, MavFrame.GLOBAL_RELATIVE_ALT_INT: MavFrame.GLOBAL_RELATIVE_ALT}

FENCE_POLYGONS = (MavCmd.NAV_FENCE_POLYGON_VERTEX_INCLUSION, MavCmd.NAV_FENCE_POLYGON_VERTEX_EXCLUSION)
NOT_MISSION_ITEMS = (*FENCE_POLYGONS, MavCmd.NAV_FENCE_CIRCLE_INCLUSION, MavCmd.NAV_FENCE_CIRCLE_EXCLUSION,
                     MavCmd.NAV_RALLY_POINT)
_ROI_COMMANDS = (MavCmd.NAV_ROI, MavCmd.DO_SET_ROI)

# Positional commands PX4 accepts in a global frame, and which params it keeps of each (1-based; "yaw" = param4 as a
# heading wrapped to [0, 360); "flag" = param > 0 kept as 0/1).
_GLOBAL_COMMANDS: dict[int, tuple[str, ...]] = {
    MavCmd.NAV_WAYPOINT: ("1", "2", "yaw"),
    MavCmd.NAV_LOITER_UNLIM: ("3", "yaw"),
    MavCmd.NAV_LOITER_TIME: ("1", "flag2", "3", "flag4"),
    MavCmd.NAV_LAND: ("2", "yaw"),
    MavCmd.NAV_TAKEOFF: ("yaw",),
    MavCmd.NAV_LOITER_TO_ALT: ("flag1", "2", "flag4"),
    MavCmd.NAV_ROI: (), MavCmd.DO_SET_ROI: (), MavCmd.DO_SET_ROI_LOCATION: (),
    MavCmd.NAV_VTOL_TAKEOFF: ("yaw",), MavCmd.NAV_VTOL_LAND: ("yaw",),
    MavCmd.CONDITION_GATE: (),
    MavCmd.NAV_FENCE_RETURN_POINT: (),
    MavCmd.NAV_FENCE_POLYGON_VERTEX_INCLUSION: ("count1",), MavCmd.NAV_FENCE_POLYGON_VERTEX_EXCLUSION: ("count1",),
    MavCmd.NAV_FENCE_CIRCLE_INCLUSION: ("1",), MavCmd.NAV_FENCE_CIRCLE_EXCLUSION: ("1",),
    MavCmd.NAV_RALLY_POINT: (),
    MavCmd.COMPONENT_ARM_DISARM: (), MavCmd.DO_AUTOTUNE_ENABLE: (),
    MavCmd.DO_LAND_START: (),  # the marker's optional position (params 5-7, command_params.py) kept, no params
}
# Commands PX4 accepts in MAV_FRAME_MISSION (params kept as sent)
_MISSION_FRAME_COMMANDS = frozenset({
    MavCmd.DO_JUMP, MavCmd.NAV_ROI, MavCmd.DO_SET_ROI, MavCmd.DO_WINCH, MavCmd.DO_GRIPPER, MavCmd.DO_CHANGE_SPEED,
    MavCmd.DO_SET_HOME, MavCmd.DO_LAND_START, MavCmd.DO_TRIGGER_CONTROL, MavCmd.DO_DIGICAM_CONTROL,
    MavCmd.DO_MOUNT_CONFIGURE, MavCmd.DO_MOUNT_CONTROL, MavCmd.DO_GIMBAL_MANAGER_PITCHYAW, MavCmd.SET_CAMERA_FOCUS,
    MavCmd.DO_GIMBAL_MANAGER_CONFIGURE, MavCmd.IMAGE_START_CAPTURE, MavCmd.IMAGE_STOP_CAPTURE,
    MavCmd.VIDEO_START_CAPTURE, MavCmd.VIDEO_STOP_CAPTURE, MavCmd.DO_CONTROL_VIDEO, MavCmd.DO_SET_CAM_TRIGG_DIST,
    MavCmd.OBLIQUE_SURVEY, MavCmd.DO_SET_CAM_TRIGG_INTERVAL, MavCmd.SET_CAMERA_MODE, MavCmd.SET_CAMERA_SOURCE,
    MavCmd.DO_VTOL_TRANSITION, MavCmd.NAV_DELAY, MavCmd.NAV_RETURN_TO_LAUNCH, MavCmd.DO_SET_ROI_WPNEXT_OFFSET,
    MavCmd.DO_SET_ROI_NONE, MavCmd.CONDITION_DELAY, MavCmd.CONDITION_DISTANCE, MavCmd.DO_SET_ACTUATOR,
    MavCmd.DO_AUTOTUNE_ENABLE, MavCmd.COMPONENT_ARM_DISARM,
})
MAV_ROI_NONE, MAV_ROI_WPNEXT, MAV_ROI_WPINDEX, MAV_ROI_LOCATION = 0, 1, 2, 3

# MISSION_CURRENT.mission_mode: 1 in a mode that flies mission items, 2 suspended (update_mission_state)
_MISSION_MODE_NAV_STATES = (NavState.AUTO_MISSION, NavState.AUTO_TAKEOFF, NavState.AUTO_LAND)
UINT16_MAX = 0xFFFF


def parse_item(msg: Any, int_mode: bool) -> tuple[int, MissionItem | None]:
    """(MAV_MISSION_RESULT, the item PX4 would keep) for a MISSION_ITEM(_INT); int_mode: it came as MISSION_ITEM_INT."""
    frame, command = msg.frame, msg.command
    int_frames = (MavFrame.GLOBAL_INT, MavFrame.GLOBAL_RELATIVE_ALT_INT)
    is_global = frame in (MavFrame.GLOBAL, MavFrame.GLOBAL_RELATIVE_ALT) or (int_mode and frame in int_frames)
    if not is_global and frame != MavFrame.MISSION:
        return MAV_MISSION_UNSUPPORTED_FRAME, None
    unused = unused_param_result(command, (msg.param1, msg.param2, msg.param3, msg.param4), msg.x, msg.y, msg.z,
                                 int_mode and is_global)
    if unused is not None:
        return unused, None
    if is_global:
        return _parse_global(msg, int_mode)
    if command not in _MISSION_FRAME_COMMANDS:
        return MAV_MISSION_UNSUPPORTED, None
    if command in _ROI_COMMANDS and int(msg.param1) not in (MAV_ROI_NONE, MAV_ROI_WPNEXT, MAV_ROI_WPINDEX):
        return MAV_MISSION_INVALID_PARAM1, None
    x, y = (msg.x, msg.y) if int_mode else (_round(msg.x), _round(msg.y))
    return MAV_MISSION_ACCEPTED, MissionItem(msg.seq, MavFrame.MISSION, command, msg.autocontinue, msg.param1,
                                             msg.param2, msg.param3, msg.param4, x, y, msg.z)


def _parse_global(msg: Any, int_mode: bool) -> tuple[int, MissionItem | None]:
    x, y = (msg.x, msg.y) if int_mode else (_round(msg.x * 1e7), _round(msg.y * 1e7))
    kept = _GLOBAL_COMMANDS.get(msg.command)
    if kept is None:
        return MAV_MISSION_UNSUPPORTED, None
    if msg.command in _ROI_COMMANDS and int(msg.param1) not in (MAV_ROI_LOCATION, MAV_ROI_NONE):
        return MAV_MISSION_INVALID_PARAM1, None
    sent = (msg.param1, msg.param2, msg.param3, msg.param4)
    params = [0.0, 0.0, 0.0, 0.0]
    for rule in kept:
        index = int(rule[-1]) - 1 if rule != "yaw" else 3
        params[index] = _keep(rule, sent[index])
    p1, p2, p3, p4 = params
    return MAV_MISSION_ACCEPTED, MissionItem(msg.seq, _INT_FRAMES[msg.frame], msg.command, msg.autocontinue,
                                             p1, p2, p3, p4, x, y, msg.z)


def _keep(rule: str, value: float) -> float:
    if rule == "yaw":
        return math.degrees(math.radians(value) % math.tau) if math.isfinite(value) else value
    if rule.startswith("flag"):
        return 1.0 if value > 0 else 0.0
    if rule.startswith("count"):
        return float(int(value + 0.5)) if math.isfinite(value) else 0.0
    return value


def _round(value: float) -> int:
    return round(value) if math.isfinite(value) else 0


def plan_check(plan_type: int, item: MissionItem) -> bool:
    """The per-plan checks PX4 makes while storing an item: no fence or rally item in a mission, no polygon vertex
    of fewer than 3 vertices in a fence."""
    if plan_type == PLAN_MISSION:
        return item.command not in NOT_MISSION_ITEMS
    if plan_type == PLAN_FENCE and item.command in FENCE_POLYGONS:
        return item.param1 >= 3
    return True


def item_message(encoder: MessageEncoder, target: tuple[int, int], item: MissionItem, current: bool, plan_type: int,
                 int_mode: bool) -> Packed:
    """The MISSION_ITEM_INT (or legacy MISSION_ITEM) PX4 sends for a stored item."""
    p = (item.param1, item.param2, item.param3, item.param4)
    if int_mode:
        return encoder.mission_item_int_encode(*target, item.seq, item.frame, item.command, int(current),
                                               item.autocontinue, *p, item.x, item.y, item.z, plan_type)
    if item.frame == MavFrame.MISSION:
        frame, x, y = MavFrame.MISSION, float(item.x), float(item.y)
    else:
        frame, x, y = _FLOAT_FRAMES[item.frame], item.lat_deg, item.lon_deg
    return encoder.mission_item_encode(*target, item.seq, frame, item.command, int(current), item.autocontinue, *p,
                                       x, y, item.z, plan_type)


def mission_current_fields(store: MissionStore, nav_state: NavState) -> tuple[int, int, int, int]:
    """MISSION_CURRENT (seq, total, mission_state, mission_mode) as send_mission_current fills it: total UINT16_MAX
    with no mission; the state from the navigator's result (mission_store.mission_state); mode 1 (active) only in
    Mission, Takeoff or Land, else 2 (suspended)."""
    count = store.count(PLAN_MISSION)
    active = nav_state in _MISSION_MODE_NAV_STATES
    return store.current_seq, count if count > 0 else UINT16_MAX, store.mission_state(active), 1 if active else 2
