"""PX4's numbering, in one place for the emulator: nav_state, custom_mode (main/sub), landed state, commands, results,
severities. What joyfly needs too (the main and sub modes, custom_mode's layout and names, MAV_RESULT) is defined in
px4common (modes.py, results.py) and imported here.

Sources (see ../shared/reference/px4-behaviour.md section 2):
- nav_state numbers: PX4 msg/versioned/VehicleStatus.msg
- custom_mode layout and main/sub numbers: src/modules/commander/px4_custom_mode.h
- mode UI names: src/lib/modes/ui.hpp
- base_mode flags per mode: src/modules/commander/ModeUtil/control_mode.cpp
"""

from __future__ import annotations

from enum import IntEnum
from typing import Final

from px4common.modes import AutoSubMode, MainMode, PosctlSubMode, custom_mode_name, encode_custom_mode
from px4common.modes import decode_custom_mode as decode_custom_mode  # the emulator imports PX4's numbering from here
from px4common.results import MavResult as MavResult


class NavState(IntEnum):
    """vehicle_status.nav_state (msg/versioned/VehicleStatus.msg)."""

    MANUAL = 0
    ALTCTL = 1
    POSCTL = 2
    AUTO_MISSION = 3
    AUTO_LOITER = 4
    AUTO_RTL = 5
    POSITION_SLOW = 6
    GUIDED_COURSE = 7
    ALTITUDE_CRUISE = 8
    ACRO = 10
    DESCEND = 12
    TERMINATION = 13
    OFFBOARD = 14
    STAB = 15
    AUTO_TAKEOFF = 17
    AUTO_LAND = 18
    AUTO_FOLLOW_TARGET = 19
    AUTO_PRECLAND = 20
    ORBIT = 21
    AUTO_VTOL_TAKEOFF = 22


class LandedState(IntEnum):
    """MAV_LANDED_STATE."""

    UNDEFINED = 0
    ON_GROUND = 1
    IN_AIR = 2
    TAKEOFF = 3
    LANDING = 4


class MavCmd(IntEnum):
    """MAV_CMD numbers (MAVLink common.xml, names without the MAV_CMD_ prefix): every command the emulator answers or
    stores, here and nowhere else.

    Answered: the commander's (Commander.cpp handle_command), the navigator's (DO_SET_MISSION_CURRENT) and the
    mavlink module's (mavlink_receiver.cpp handle_message_command_both); commander/commands.py and
    mavlink/link_commands.py map them to their handlers. Stored: the mission, geofence and rally items PX4 accepts
    in an upload (mavlink_mission.cpp parse_mavlink_mission_item; protocols/mission_items.py). PX4 keeps MAVLink's
    numbering for vehicle_command and mission_item internally, and so do we.
    """

    NAV_WAYPOINT = 16
    NAV_LOITER_UNLIM = 17
    NAV_LOITER_TIME = 19
    NAV_RETURN_TO_LAUNCH = 20
    NAV_LAND = 21
    NAV_TAKEOFF = 22
    NAV_LOITER_TO_ALT = 31
    DO_ORBIT = 34
    NAV_ROI = 80
    NAV_VTOL_TAKEOFF = 84
    NAV_VTOL_LAND = 85
    NAV_DELAY = 93
    CONDITION_DELAY = 112
    CONDITION_DISTANCE = 114
    DO_SET_MODE = 176
    DO_JUMP = 177
    DO_CHANGE_SPEED = 178
    DO_SET_HOME = 179
    DO_FLIGHTTERMINATION = 185
    DO_CHANGE_ALTITUDE = 186
    DO_SET_ACTUATOR = 187
    DO_LAND_START = 189
    DO_REPOSITION = 192
    DO_SET_ROI_LOCATION = 195
    DO_SET_ROI_WPNEXT_OFFSET = 196
    DO_SET_ROI_NONE = 197
    DO_CONTROL_VIDEO = 200
    DO_SET_ROI = 201
    DO_DIGICAM_CONTROL = 203
    DO_MOUNT_CONFIGURE = 204
    DO_MOUNT_CONTROL = 205
    DO_SET_CAM_TRIGG_DIST = 206
    DO_GRIPPER = 211
    DO_AUTOTUNE_ENABLE = 212
    DO_SET_CAM_TRIGG_INTERVAL = 214
    DO_SET_MISSION_CURRENT = 224
    PREFLIGHT_CALIBRATION = 241
    PREFLIGHT_REBOOT_SHUTDOWN = 246
    OBLIQUE_SURVEY = 260
    MISSION_START = 300
    COMPONENT_ARM_DISARM = 400
    RUN_PREARM_CHECKS = 401
    GET_HOME_POSITION = 410  # legacy alias of REQUEST_MESSAGE(HOME_POSITION), PX4 <= v1.17
    INJECT_FAILURE = 420
    GET_MESSAGE_INTERVAL = 510
    SET_MESSAGE_INTERVAL = 511
    REQUEST_MESSAGE = 512
    REQUEST_PROTOCOL_VERSION = 519  # legacy alias of REQUEST_MESSAGE(PROTOCOL_VERSION), PX4 <= v1.17
    REQUEST_AUTOPILOT_CAPABILITIES = 520  # legacy alias of REQUEST_MESSAGE(AUTOPILOT_VERSION), PX4 <= v1.17
    SET_CAMERA_MODE = 530
    SET_CAMERA_FOCUS = 532
    SET_CAMERA_SOURCE = 534
    DO_GIMBAL_MANAGER_PITCHYAW = 1000
    DO_GIMBAL_MANAGER_CONFIGURE = 1001
    IMAGE_START_CAPTURE = 2000
    IMAGE_STOP_CAPTURE = 2001
    DO_TRIGGER_CONTROL = 2003
    VIDEO_START_CAPTURE = 2500
    VIDEO_STOP_CAPTURE = 2501
    DO_VTOL_TRANSITION = 3000
    CONDITION_GATE = 4501
    NAV_FENCE_RETURN_POINT = 5000
    NAV_FENCE_POLYGON_VERTEX_INCLUSION = 5001
    NAV_FENCE_POLYGON_VERTEX_EXCLUSION = 5002
    NAV_FENCE_CIRCLE_INCLUSION = 5003
    NAV_FENCE_CIRCLE_EXCLUSION = 5004
    NAV_RALLY_POINT = 5100
    DO_WINCH = 42600


class MavFrame(IntEnum):
    """MAV_FRAME numbers (common.xml) of the frames the emulator reads or sends."""

    GLOBAL = 0  # altitude above mean sea level
    LOCAL_NED = 1
    MISSION = 2  # a mission item without a position: its params are kept as sent
    GLOBAL_RELATIVE_ALT = 3  # altitude above home
    GLOBAL_INT = 5
    GLOBAL_RELATIVE_ALT_INT = 6
    BODY_NED = 8
    GLOBAL_TERRAIN_ALT_INT = 11
    BODY_FRD = 12


# The global frames of a mission, fence or rally item, by what their altitude is measured from
ABSOLUTE_FRAMES: Final = frozenset({MavFrame.GLOBAL, MavFrame.GLOBAL_INT})
RELATIVE_FRAMES: Final = frozenset({MavFrame.GLOBAL_RELATIVE_ALT, MavFrame.GLOBAL_RELATIVE_ALT_INT})
GLOBAL_FRAMES: Final = ABSOLUTE_FRAMES | RELATIVE_FRAMES


class Severity(IntEnum):
    """MAV_SEVERITY; PX4's mavlink_log_critical -> CRITICAL, _warning -> WARNING, _info -> INFO."""

    EMERGENCY = 0
    ALERT = 1
    CRITICAL = 2
    ERROR = 3
    WARNING = 4
    NOTICE = 5
    INFO = 6
    DEBUG = 7


class MavState(IntEnum):
    """MAV_STATE for HEARTBEAT.system_status."""

    UNINIT = 0
    BOOT = 1
    CALIBRATING = 2
    STANDBY = 3
    ACTIVE = 4
    CRITICAL = 5
    EMERGENCY = 6
    POWEROFF = 7
    FLIGHT_TERMINATION = 8


# MAV_MODE_FLAG bits (MAVLink minimal.xml)
MODE_FLAG_CUSTOM_MODE_ENABLED: Final = 1
MODE_FLAG_TEST_ENABLED: Final = 2
MODE_FLAG_AUTO_ENABLED: Final = 4
MODE_FLAG_GUIDED_ENABLED: Final = 8
MODE_FLAG_STABILIZE_ENABLED: Final = 16
MODE_FLAG_HIL_ENABLED: Final = 32
MODE_FLAG_MANUAL_INPUT_ENABLED: Final = 64
MODE_FLAG_SAFETY_ARMED: Final = 128

# nav_state -> (main_mode, sub_mode) as get_px4_custom_mode() encodes it (v1.15-v1.17: DESCEND -> AUTO.LAND).
_NAV_TO_MAIN_SUB: Final[dict[NavState, tuple[int, int]]] = {
    NavState.MANUAL: (MainMode.MANUAL, 0),
    NavState.ALTCTL: (MainMode.ALTCTL, 0),
    NavState.POSCTL: (MainMode.POSCTL, PosctlSubMode.POSCTL),
    NavState.AUTO_MISSION: (MainMode.AUTO, AutoSubMode.MISSION),
    NavState.AUTO_LOITER: (MainMode.AUTO, AutoSubMode.LOITER),
    NavState.AUTO_RTL: (MainMode.AUTO, AutoSubMode.RTL),
    NavState.POSITION_SLOW: (MainMode.POSCTL, PosctlSubMode.SLOW),
    NavState.GUIDED_COURSE: (MainMode.AUTO, AutoSubMode.GUIDED_COURSE),
    NavState.ALTITUDE_CRUISE: (MainMode.ALTITUDE_CRUISE, 0),
    NavState.ACRO: (MainMode.ACRO, 0),
    NavState.DESCEND: (MainMode.AUTO, AutoSubMode.LAND),
    NavState.TERMINATION: (MainMode.TERMINATION, 0),
    NavState.OFFBOARD: (MainMode.OFFBOARD, 0),
    NavState.STAB: (MainMode.STABILIZED, 0),
    NavState.AUTO_TAKEOFF: (MainMode.AUTO, AutoSubMode.TAKEOFF),
    NavState.AUTO_LAND: (MainMode.AUTO, AutoSubMode.LAND),
    NavState.AUTO_FOLLOW_TARGET: (MainMode.AUTO, AutoSubMode.FOLLOW_TARGET),
    NavState.AUTO_PRECLAND: (MainMode.AUTO, AutoSubMode.PRECLAND),
    NavState.ORBIT: (MainMode.POSCTL, PosctlSubMode.ORBIT),
    NavState.AUTO_VTOL_TAKEOFF: (MainMode.AUTO, AutoSubMode.VTOL_TAKEOFF),
}

# Mode names from src/lib/modes/ui.hpp, used in "Switching to %s is currently not available".
UI_NAMES: Final[dict[NavState, str]] = {
    NavState.MANUAL: "Manual",
    NavState.ALTCTL: "Altitude",
    NavState.POSCTL: "Position",
    NavState.AUTO_MISSION: "Mission",
    NavState.AUTO_LOITER: "Hold",
    NavState.AUTO_RTL: "Return",
    NavState.POSITION_SLOW: "Position Slow",
    NavState.GUIDED_COURSE: "Guided Course",
    NavState.ALTITUDE_CRUISE: "Altitude Cruise",
    NavState.ACRO: "Acro",
    NavState.DESCEND: "Descend",
    NavState.TERMINATION: "Termination",
    NavState.OFFBOARD: "Offboard",
    NavState.STAB: "Stabilized",
    NavState.AUTO_TAKEOFF: "Takeoff",
    NavState.AUTO_LAND: "Land",
    NavState.AUTO_FOLLOW_TARGET: "Follow Target",
    NavState.AUTO_PRECLAND: "Precision Landing",
    NavState.ORBIT: "Orbit",
    NavState.AUTO_VTOL_TAKEOFF: "VTOL Takeoff",
}

# `commander mode <name>` (Commander.cpp custom_command) -> nav_state
SHELL_MODE_NAMES: dict[str, NavState] = {
    "manual": NavState.MANUAL,
    "altctl": NavState.ALTCTL,
    "posctl": NavState.POSCTL,
    "position:slow": NavState.POSITION_SLOW,
    "altitude_cruise": NavState.ALTITUDE_CRUISE,
    "auto:mission": NavState.AUTO_MISSION,
    "auto:loiter": NavState.AUTO_LOITER,
    "auto:course": NavState.GUIDED_COURSE,
    "auto:rtl": NavState.AUTO_RTL,
    "acro": NavState.ACRO,
    "offboard": NavState.OFFBOARD,
    "stabilized": NavState.STAB,
    "auto:takeoff": NavState.AUTO_TAKEOFF,
    "auto:land": NavState.AUTO_LAND,
    "auto:precland": NavState.AUTO_PRECLAND,
}

AUTO_MODES: Final = frozenset(
    {NavState.AUTO_MISSION, NavState.AUTO_LOITER, NavState.AUTO_RTL, NavState.AUTO_TAKEOFF,
     NavState.AUTO_LAND, NavState.AUTO_FOLLOW_TARGET, NavState.AUTO_PRECLAND,
     NavState.AUTO_VTOL_TAKEOFF, NavState.GUIDED_COURSE, NavState.DESCEND}
)


# control_mode flag_control_manual_enabled modes, split by who controls the thrust (ModeUtil/control_mode.cpp):
# the climb-rate modes (the sticks command a climb rate) and the manual-thrust ones (the throttle is the thrust)
CLIMB_RATE_MANUAL_MODES: Final = frozenset({NavState.ALTCTL, NavState.POSCTL, NavState.POSITION_SLOW,
                                            NavState.ALTITUDE_CRUISE})
MANUAL_THRUST_MODES: Final = frozenset({NavState.MANUAL, NavState.STAB, NavState.ACRO})
MANUAL_MODES: Final = CLIMB_RATE_MANUAL_MODES | MANUAL_THRUST_MODES


def main_sub(nav_state: NavState) -> tuple[int, int]:
    return _NAV_TO_MAIN_SUB[nav_state]


def custom_mode(nav_state: NavState) -> int:
    """HEARTBEAT.custom_mode of a nav_state."""
    return encode_custom_mode(*_NAV_TO_MAIN_SUB[nav_state])


def mode_name(nav_state: NavState) -> str:
    """The MAVROS/pymavlink name of a nav_state, e.g. 'AUTO.LOITER', 'OFFBOARD'."""
    return custom_mode_name(custom_mode(nav_state))


def nav_state_from_main_sub(main: int, sub: int) -> NavState | None:
    """DO_SET_MODE with the custom bit set -> nav_state, as Commander.cpp handle_command does; None if unsupported."""
    if main == MainMode.MANUAL:
        return NavState.MANUAL
    if main == MainMode.ALTCTL:
        return NavState.ALTCTL
    if main == MainMode.ALTITUDE_CRUISE:
        return NavState.ALTITUDE_CRUISE
    if main == MainMode.POSCTL:
        return NavState.POSITION_SLOW if sub == PosctlSubMode.SLOW else NavState.POSCTL
    if main == MainMode.AUTO:
        if sub == 0:
            return NavState.AUTO_MISSION
        return _AUTO_SUB_TO_NAV.get(sub)
    if main == MainMode.ACRO:
        return NavState.ACRO
    if main == MainMode.STABILIZED:
        return NavState.STAB
    if main == MainMode.OFFBOARD:
        return NavState.OFFBOARD
    return None


_AUTO_SUB_TO_NAV: Final[dict[int, NavState]] = {
    AutoSubMode.LOITER: NavState.AUTO_LOITER,
    AutoSubMode.MISSION: NavState.AUTO_MISSION,
    AutoSubMode.RTL: NavState.AUTO_RTL,
    AutoSubMode.TAKEOFF: NavState.AUTO_TAKEOFF,
    AutoSubMode.LAND: NavState.AUTO_LAND,
    AutoSubMode.FOLLOW_TARGET: NavState.AUTO_FOLLOW_TARGET,
    AutoSubMode.PRECLAND: NavState.AUTO_PRECLAND,
    AutoSubMode.GUIDED_COURSE: NavState.GUIDED_COURSE,
}
