"""Mission items on the wire: PX4's checks on an uploaded item, and the item PX4 sends back on a download.

After src/modules/mavlink/mavlink_mission.cpp (parse_mavlink_mission_item, format_mavlink_mission_item): an item is
either positional (a global frame: lat/lon/alt) or a "mission frame" command (MAV_FRAME_MISSION: seven raw params);
any other frame (local, body, terrain) is refused with MAV_MISSION_UNSUPPORTED_FRAME, a command PX4 does not know in
that frame with MAV_MISSION_UNSUPPORTED. PX4 keeps its own parsed item, not the message, so a download returns what it
kept: the altitude reference as the INT or float variant of the global frame, and only the params the command uses
(e.g. a waypoint's pass radius comes back as 0, its yaw wrapped into [0, 360)).

One check is taken from real PX4 main (../shared/reference/px4-mission/cases.json `bad.rtl_global_frame_zero_xy`)
rather than from the older source read: a positional item at latitude 0 and longitude 0 is refused with
MAV_MISSION_INVALID_PARAM5_X (PX4 main answers so for an RTL item in a global frame with x = y = 0).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from sitl_emu.flight.mission_store import PLAN_FENCE, PLAN_MISSION, MissionItem, MissionStore
from sitl_emu.px4 import NavState

if TYPE_CHECKING:
    from pymavlink.dialects.v20.development import MAVLink, MAVLink_message

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

# MAV_FRAME
FRAME_GLOBAL, FRAME_MISSION, FRAME_GLOBAL_REL = 0, 2, 3
FRAME_GLOBAL_INT, FRAME_GLOBAL_REL_INT = 5, 6
_INT_FRAMES = {FRAME_GLOBAL: FRAME_GLOBAL_INT, FRAME_GLOBAL_REL: FRAME_GLOBAL_REL_INT,
               FRAME_GLOBAL_INT: FRAME_GLOBAL_INT, FRAME_GLOBAL_REL_INT: FRAME_GLOBAL_REL_INT}
_FLOAT_FRAMES = {FRAME_GLOBAL_INT: FRAME_GLOBAL, FRAME_GLOBAL_REL_INT: FRAME_GLOBAL_REL}

# MAV_CMD numbers used below
WAYPOINT, LOITER_UNLIM, LOITER_TIME, RTL, LAND, TAKEOFF, LOITER_TO_ALT = 16, 17, 19, 20, 21, 22, 31
NAV_ROI, DO_SET_ROI, DO_SET_ROI_LOCATION, VTOL_TAKEOFF, VTOL_LAND = 80, 201, 195, 84, 85
FENCE_RETURN, FENCE_POLY_IN, FENCE_POLY_EX, FENCE_CIRCLE_IN, FENCE_CIRCLE_EX, RALLY_POINT = (
    5000, 5001, 5002, 5003, 5004, 5100)
FENCE_POLYGONS = (FENCE_POLY_IN, FENCE_POLY_EX)
NOT_MISSION_ITEMS = (FENCE_POLY_IN, FENCE_POLY_EX, FENCE_CIRCLE_IN, FENCE_CIRCLE_EX, RALLY_POINT)

# Positional commands PX4 accepts in a global frame, and which params it keeps of each (1-based; "yaw" = param4 as a
# heading wrapped to [0, 360); "flag" = param > 0 kept as 0/1).
_GLOBAL_COMMANDS: dict[int, tuple[str, ...]] = {
    WAYPOINT: ("1", "2", "yaw"), LOITER_UNLIM: ("3", "yaw"), LOITER_TIME: ("1", "flag2", "3", "flag4"),
    LAND: ("2", "yaw"), TAKEOFF: ("yaw",), LOITER_TO_ALT: ("flag1", "2", "flag4"),
    NAV_ROI: (), DO_SET_ROI: (), DO_SET_ROI_LOCATION: (), VTOL_TAKEOFF: ("yaw",), VTOL_LAND: ("yaw",),
    4501: (), FENCE_RETURN: (), FENCE_POLY_IN: ("count1",), FENCE_POLY_EX: ("count1",),
    FENCE_CIRCLE_IN: ("1",), FENCE_CIRCLE_EX: ("1",), RALLY_POINT: (), 400: (), 212: (),
}
# Commands PX4 accepts in MAV_FRAME_MISSION (params kept as sent)
_MISSION_FRAME_COMMANDS = frozenset({
    177, NAV_ROI, DO_SET_ROI, 42600, 211, 178, 179, 189, 2003, 203, 204, 205, 1000, 532, 1001, 2000, 2001, 2500,
    2501, 200, 206, 260, 214, 530, 534, 3000, 93, RTL, 196, 197, 112, 114, 187, 212, 400,
})
MAV_ROI_NONE, MAV_ROI_WPNEXT, MAV_ROI_WPINDEX, MAV_ROI_LOCATION = 0, 1, 2, 3

# MISSION_CURRENT.mission_mode: 1 in a mode that flies mission items, 2 suspended (update_mission_state)
_MISSION_MODE_NAV_STATES = (NavState.AUTO_MISSION, NavState.AUTO_TAKEOFF, NavState.AUTO_LAND)
UINT16_MAX = 0xFFFF


def parse_item(msg: Any, int_mode: bool) -> tuple[int, MissionItem | None]:
    """(MAV_MISSION_RESULT, the item PX4 would keep) for a MISSION_ITEM(_INT); int_mode: it came as MISSION_ITEM_INT."""
    frame, command = msg.frame, msg.command
    if frame in (FRAME_GLOBAL, FRAME_GLOBAL_REL) or (int_mode and frame in (FRAME_GLOBAL_INT, FRAME_GLOBAL_REL_INT)):
        return _parse_global(msg, int_mode)
    if frame != FRAME_MISSION:
        return MAV_MISSION_UNSUPPORTED_FRAME, None
    if command not in _MISSION_FRAME_COMMANDS:
        return MAV_MISSION_UNSUPPORTED, None
    if command in (NAV_ROI, DO_SET_ROI) and int(msg.param1) not in (MAV_ROI_NONE, MAV_ROI_WPNEXT, MAV_ROI_WPINDEX):
        return MAV_MISSION_INVALID_PARAM1, None
    x, y = (msg.x, msg.y) if int_mode else (_round(msg.x), _round(msg.y))
    return MAV_MISSION_ACCEPTED, MissionItem(msg.seq, FRAME_MISSION, command, msg.autocontinue, msg.param1,
                                             msg.param2, msg.param3, msg.param4, x, y, msg.z)


def _parse_global(msg: Any, int_mode: bool) -> tuple[int, MissionItem | None]:
    x, y = (msg.x, msg.y) if int_mode else (_round(msg.x * 1e7), _round(msg.y * 1e7))
    if x == 0 and y == 0:
        return MAV_MISSION_INVALID_PARAM5_X, None  # PX4 main (reference), see the module docstring
    kept = _GLOBAL_COMMANDS.get(msg.command)
    if kept is None:
        return MAV_MISSION_UNSUPPORTED, None
    if msg.command in (NAV_ROI, DO_SET_ROI) and int(msg.param1) not in (MAV_ROI_LOCATION, MAV_ROI_NONE):
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


def item_message(mav: MAVLink, target: tuple[int, int], item: MissionItem, current: bool, plan_type: int,
                 int_mode: bool) -> MAVLink_message:
    """The MISSION_ITEM_INT (or legacy MISSION_ITEM) PX4 sends for a stored item."""
    p = (item.param1, item.param2, item.param3, item.param4)
    if int_mode:
        return mav.mission_item_int_encode(*target, item.seq, item.frame, item.command, int(current),
                                           item.autocontinue, *p, item.x, item.y, item.z, plan_type)
    if item.frame == FRAME_MISSION:
        frame, x, y = FRAME_MISSION, float(item.x), float(item.y)
    else:
        frame, x, y = _FLOAT_FRAMES[item.frame], item.lat_deg, item.lon_deg
    return mav.mission_item_encode(*target, item.seq, frame, item.command, int(current), item.autocontinue, *p,
                                   x, y, item.z, plan_type)


def mission_current_fields(store: MissionStore, nav_state: NavState) -> tuple[int, int, int, int]:
    """MISSION_CURRENT (seq, total, mission_state, mission_mode) as send_mission_current fills it: total UINT16_MAX
    with no mission; the state from the navigator's result (mission_store.mission_state); mode 1 (active) only in
    Mission, Takeoff or Land, else 2 (suspended)."""
    count = store.count(PLAN_MISSION)
    active = nav_state in _MISSION_MODE_NAV_STATES
    return store.current_seq, count if count > 0 else UINT16_MAX, store.mission_state(active), 1 if active else 2
