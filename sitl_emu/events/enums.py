"""The PX4 event enums the emulator's events carry (PX4 src/lib/events/enums.json, namespace "px4"): their base
type and entries (value -> name, the description a ground station shows), and the maps from the emulator's terms.

failsafe_action_t / failsafe_cause_t are failsafe/framework.h's Action and Cause (notifyUser casts one to the other);
health_component_t and navigation_mode_group_t are bitfields (one bit per component; bit n = nav_state n, as
Report::getModeGroup maps them), carried by the health and arming check report (HealthAndArmingChecks/Common.cpp).

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
    is_bitfield: bool = False

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

FAILSAFE_ACTION = EventEnum("failsafe_action_t", "uint8_t", "failsafe action", (
    (0, "none", ""), (1, "warn", "warning"), (2, "fallback_posctrl", "fallback to position control"),
    (3, "fallback_altctrl", "fallback to altitude control"), (4, "fallback_stabilized", "fallback to stabilized"),
    (5, "hold", "hold"), (6, "rtl", "RTL"), (7, "land", "land"), (8, "descend", "descend"), (9, "disarm", "disarm"),
    (10, "terminate", "terminate")))

FAILSAFE_CAUSE = EventEnum("failsafe_cause_t", "uint8_t", "Cause for entering failsafe", (
    (0, "generic", ""), (1, "manual_control_loss", "manual control loss"),
    (2, "gcs_connection_loss", "GCS connection loss"), (3, "low_battery_level", "low battery level"),
    (4, "critical_battery_level", "critical battery level"),
    (5, "emergency_battery_level", "emergency battery level")))

HEALTH_COMPONENT: EventEnum = EventEnum("health_component_t", "uint32_t", "Bitfield for subsystems & components", tuple(
    (1 << i, name, text) for i, (name, text) in enumerate((
        ("none", "None"), ("absolute_pressure", "Absolute pressure"),
        ("differential_pressure", "Differential pressure"), ("gps", "GPS"), ("optical_flow", "Optical flow"),
        ("vision_position", "Vision position estimate"), ("distance_sensor", "Distance sensor"),
        ("remote_control", "Remote Control (RC or Joystick)"), ("motors_escs", "Motors/ESCs"), ("utm", "UTM"),
        ("logging", "Logging"), ("battery", "Battery"), ("communication_links", "Communication links"),
        ("rate_controller", "Rate controller"), ("attitude_controller", "Attitude controller"),
        ("position_controller", "Position controller"), ("attitude_estimate", "Attitude estimate"),
        ("local_position_estimate", "Local position estimate"), ("mission", "Mission"), ("avoidance", "Avoidance"),
        ("system", "System"), ("camera", "Camera"), ("gimbal", "Gimbal"), ("payload", "Payload"),
        ("global_position_estimate", "Global position estimate"), ("storage", "Storage"),
        ("parachute", "Parachute"), ("magnetometer", "Magnetometer"), ("accel", "Accelerometer"),
        ("gyro", "Gyroscope"), ("open_drone_id", "Open Drone ID system")))), is_bitfield=True)

NAVIGATION_MODE_GROUP: EventEnum = EventEnum(
    "navigation_mode_group_t", "uint32_t", "Navigation/flight mode group bits. All modes within a group share the "
    "same arming checks. For now we directly map group == mode.", tuple((1 << bit, name, text) for bit, name, text in (
        (0, "manual", "Fully manual mode (w/o any controller support)"), (1, "altctl", "Altitude mode"),
        (2, "posctl", "Position mode"), (3, "mission", "Mission mode"), (4, "loiter", "Loiter"), (5, "rtl", "RTL"),
        (10, "acro", "Acro"), (14, "offboard", "Offboard"), (15, "stab", "Stabilized"), (17, "takeoff", "Takeoff"),
        (18, "land", "Land"), (19, "follow_target", "Follow Target"), (20, "precland", "Precision Land"),
        (21, "orbit", "Orbit"), (22, "vtol_takeoff", "VTOL Takeoff"))) + tuple(
        (1 << (22 + n), f"external{n}", f"External {n}") for n in range(1, 9)), is_bitfield=True)

ENUMS: tuple[EventEnum, ...] = (ARM_DISARM_REASON, NAVIGATION_MODE, FAILSAFE_ACTION, FAILSAFE_CAUSE, HEALTH_COMPONENT,
                                NAVIGATION_MODE_GROUP)


def qualified(e: EventEnum) -> str:
    """The enum as an argument type names it: "px4::failsafe_action_t"."""
    return f"{NAMESPACE}::{e.name}"


def health_component_index(name: str) -> int:
    """HealthComponentIndex: the bit number of a health component (what a check event carries)."""
    return next(v for v, n, _ in HEALTH_COMPONENT.entries if n == name).bit_length() - 1

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
