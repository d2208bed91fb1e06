"""PX4's flight modes as the wire carries them: HEARTBEAT.custom_mode and MAV_CMD_DO_SET_MODE's main and sub mode.

Source: src/modules/commander/px4_custom_mode.h (union px4_custom_mode: custom_mode = sub_mode << 24 | main_mode << 16,
the PX4_CUSTOM_MAIN_MODE_* and PX4_CUSTOM_SUB_MODE_* numbers). The names are MAVROS's and pymavlink's
("AUTO.LOITER", "OFFBOARD"), which QGroundControl users know too.
"""

from __future__ import annotations

from enum import IntEnum


class MainMode(IntEnum):
    MANUAL = 1
    ALTCTL = 2
    POSCTL = 3
    AUTO = 4
    ACRO = 5
    OFFBOARD = 6
    STABILIZED = 7
    RATTITUDE_LEGACY = 8
    SIMPLE = 9
    TERMINATION = 10
    ALTITUDE_CRUISE = 11


class AutoSubMode(IntEnum):
    READY = 1
    TAKEOFF = 2
    LOITER = 3
    MISSION = 4
    RTL = 5
    LAND = 6
    FOLLOW_TARGET = 8
    PRECLAND = 9
    VTOL_TAKEOFF = 10
    GUIDED_COURSE = 19
    DESCEND = 20


class PosctlSubMode(IntEnum):
    POSCTL = 0
    ORBIT = 1
    SLOW = 2


# The main modes' names (AUTO is named by its sub mode: "AUTO.LOITER")
MAIN_NAMES: dict[int, str] = {
    MainMode.MANUAL: "MANUAL",
    MainMode.ALTCTL: "ALTCTL",
    MainMode.POSCTL: "POSCTL",
    MainMode.ACRO: "ACRO",
    MainMode.OFFBOARD: "OFFBOARD",
    MainMode.STABILIZED: "STABILIZED",
    MainMode.RATTITUDE_LEGACY: "RATTITUDE",
    MainMode.TERMINATION: "TERMINATION",
    MainMode.ALTITUDE_CRUISE: "ALTITUDE_CRUISE",
}


def encode_custom_mode(main: int, sub: int = 0) -> int:
    """HEARTBEAT.custom_mode of a main and sub mode: (sub << 24) | (main << 16)."""
    return (int(sub) << 24) | (int(main) << 16)


def decode_custom_mode(custom_mode: int) -> tuple[int, int]:
    """custom_mode -> (main_mode, sub_mode)."""
    return (custom_mode >> 16) & 0xFF, (custom_mode >> 24) & 0xFF


def main_mode(custom_mode: int) -> int:
    """The main mode (MainMode.POSCTL, MainMode.AUTO...) of a custom_mode."""
    return (custom_mode >> 16) & 0xFF


def custom_mode_name(custom_mode: int) -> str:
    """The name of a custom_mode ("OFFBOARD", "AUTO.LOITER"); "CMODE(n)" for one PX4 does not define."""
    main, sub = decode_custom_mode(custom_mode)
    if main == MainMode.AUTO:
        known = sub in AutoSubMode._value2member_map_
        return f"AUTO.{AutoSubMode(sub).name}" if known else f"CMODE({custom_mode})"
    return MAIN_NAMES.get(main, f"CMODE({custom_mode})")
