"""The PX4 event enums the emulator's events carry (PX4 src/lib/events/enums.json, namespace "px4"): their base
type and entries (value -> name, the description a ground station shows), and the maps from the emulator's terms.

navigation_mode_t follows mode_util::navigation_mode (commander/ModeUtil/conversions.hpp): one entry per nav_state a
user can select, `unknown` (255) for the others (Descend, Termination). arm_disarm_reason_t's descriptions are
what Commander.cpp's arm_disarm_reason_str prints after "Armed by".
"""

from __future__ import annotations

from dataclasses import dataclass

from sitl_emu.px4 import NavState

NAMESPACE = "px4"


@dataclass(frozen=True, slots=True)
class EventEnum:
    name: str  # without the namespace: "arm_disarm_reason_t"
    base_type: str
    description: str
    entries: tuple[tuple[int, str, str], ...]  # (value, name, description)

    def value_of(self, description: str) -> int | None:
        return next((v for v, _, d in self.entries if d == description), None)


ARM_DISARM_REASON = EventEnum("arm_disarm_reason_t", "uint8_t", "Reason for arming/disarming", (
    (0, "transition_to_standby", "Transition to standby"), (1, "rc_stick", "RC"), (2, "rc_switch", "RC (switch)"),
    (3, "command_internal", "internal command"), (4, "command_external", "external command"),
    (5, "mission_start", "mission start"), (6, "auto_disarm_land", "landing"),
    (7, "auto_disarm_preflight", "auto preflight disarming"), (8, "kill_switch", "kill switch"),
    (9, "lockdown", "lockdown"), (10, "failure_detector", "failure detector"), (11, "shutdown", "shutdown request"),
    (12, "unit_test", "unit tests"), (13, "rc_button", "RC (button)"), (14, "failsafe", "failsafe")))

NAVIGATION_MODE = EventEnum("navigation_mode_t", "uint8_t", "Flight mode", (
    (0, "manual", "Manual"), (1, "altctl", "Altitude control"), (2, "posctl", "Position control"),
    (3, "auto_mission", "Mission"), (4, "auto_loiter", "Hold"), (5, "auto_rtl", "RTL"), (6, "acro", "Acro"),
    (7, "offboard", "Offboard"), (8, "stab", "Stabilized"), (9, "position_slow", "Position Slow"),
    (10, "auto_takeoff", "Takeoff"), (11, "auto_land", "Land"), (12, "auto_follow_target", "Follow Target"),
    (13, "auto_precland", "Precision Landing"), (14, "orbit", "Orbit"), (15, "auto_vtol_takeoff", "Vtol Takeoff"),
    (255, "unknown", "[Unknown]")))

ENUMS: tuple[EventEnum, ...] = (ARM_DISARM_REASON, NAVIGATION_MODE)

NAVIGATION_MODE_UNKNOWN = 255
_NAVIGATION_MODE_OF: dict[NavState, int] = {
    NavState.MANUAL: 0, NavState.ALTCTL: 1, NavState.POSCTL: 2, NavState.AUTO_MISSION: 3, NavState.AUTO_LOITER: 4,
    NavState.AUTO_RTL: 5, NavState.ACRO: 6, NavState.OFFBOARD: 7, NavState.STAB: 8, NavState.POSITION_SLOW: 9,
    NavState.AUTO_TAKEOFF: 10, NavState.AUTO_LAND: 11, NavState.AUTO_FOLLOW_TARGET: 12, NavState.AUTO_PRECLAND: 13,
    NavState.ORBIT: 14, NavState.AUTO_VTOL_TAKEOFF: 15,
}

# the emulator's own word for a reason PX4 names otherwise (commander.py's stick gestures are PX4's rc_stick)
_REASON_ALIASES = {"stick gesture": "RC", "kill-switch": "kill switch"}


def navigation_mode(nav_state: NavState) -> int:
    return _NAVIGATION_MODE_OF.get(nav_state, NAVIGATION_MODE_UNKNOWN)


def arm_disarm_reason(text: str) -> int | None:
    """The reason value for the words after "Armed by" / "Disarmed by"."""
    return ARM_DISARM_REASON.value_of(_REASON_ALIASES.get(text, text))
