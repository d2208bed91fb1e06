"""The events of PX4's health and arming check report (src/modules/commander/HealthAndArmingChecks/Common.cpp
Report::report, and the checks under checks/), which QGroundControl's arming-check and health panels show.

A report is a burst of events: commander_arming_check_summary (chunk 0; the arming checks' error and warning
components; can_arm and can_run, one bit per nav_state), one event per failing check, then commander_health_summary
(chunk 0; the components present, in error, in warning). A check event's first two arguments are the modes it
affects (navigation_mode_group_t; all modes when the check blocks none) and its health component's bit number, as
Report::armingCheckFailure adds them; its log level decides whether it counts as an error (up to Error) or a warning.
The checks the emulator models: batteryCheck.cpp (the warning level), geofenceCheck.cpp, rcAndDataLinkCheck.cpp (the
ground-station link) and modeCheck.cpp (the mode requirements); their messages are PX4's (the geofence ones as PX4
main words its legacy texts).
"""

from __future__ import annotations

from typing import Final

from sitl_emu.events import enums
from sitl_emu.events.definition import EventDefinition
from sitl_emu.events.library import Log

_COMPONENTS = enums.qualified(enums.HEALTH_COMPONENT)
_MODES = enums.qualified(enums.NAVIGATION_MODE_GROUP)

ARMING_CHECK_SUMMARY = EventDefinition(
    "commander_arming_check_summary", "Arming check summary event",
    ("uint8_t", _COMPONENTS, _COMPONENTS, _MODES, _MODES), Log.PROTOCOL, group="arming_check", type="summary")
HEALTH_SUMMARY = EventDefinition(
    "commander_health_summary", "Health report summary event", ("uint8_t", _COMPONENTS, _COMPONENTS, _COMPONENTS),
    Log.PROTOCOL, group="health", type="summary")


def _check(name: str, message: str, level: Log) -> EventDefinition:
    return EventDefinition(name, message, (_MODES, "uint8_t"), level, group="arming_check")


CANNOT_TAKEOFF = _check("check_modes_cannot_takeoff", "Mode not suitable for arming", Log.INFO)
ATTITUDE = _check("check_modes_attitude", "No valid attitude estimate", Log.CRITICAL)
LOCAL_POSITION = _check("check_modes_local_pos", "No valid local position estimate", Log.ERROR)
GLOBAL_POSITION = _check("check_modes_global_pos", "No valid global position estimate", Log.ERROR)
LOCAL_ALTITUDE = _check("check_modes_local_alt", "No valid altitude estimate", Log.CRITICAL)
MISSION = _check("check_modes_mission", "No valid mission available", Log.INFO)
OFFBOARD_SIGNAL = _check("check_modes_offboard_signal", "No offboard signal", Log.ERROR)
HOME_POSITION = _check("check_modes_home_position", "Home position not set", Log.INFO)
# Error when COM_RC_IN_MODE disables stick input, else Warning (the level is the call's, not the definition's)
MANUAL_CONTROL = _check("check_modes_manual_control", "No manual control input", Log.WARNING)
GEOFENCE_MAX_DISTANCE = _check("check_gf_violation_max_hor_dist", "Geofence: exceeding maximum distance to Home",
                               Log.ERROR)
GEOFENCE_MAX_ALTITUDE = _check("check_gf_violation_max_alt", "Geofence: exceeding maximum altitude above Home",
                               Log.ERROR)
GEOFENCE_CUSTOM = _check("check_gf_violation_custom_gf", "Geofence: approaching or outside geofence", Log.ERROR)
# Critical from the critical level on (or below COM_ARM_BAT_MIN), else Warning
BATTERY_LOW = _check("check_battery_low", "Low battery", Log.WARNING)
BATTERY_CRITICAL = _check("check_battery_critical", "Critical battery", Log.CRITICAL)
BATTERY_EMERGENCY = _check("check_battery_emergency", "Emergency battery level", Log.CRITICAL)
# Error when NAV_DLL_ACT requires the link, else Info
NO_DATALINK = _check("check_rc_dl_no_dllink", "No connection to the ground control station", Log.INFO)

DEFINITIONS: Final = (ARMING_CHECK_SUMMARY, HEALTH_SUMMARY, CANNOT_TAKEOFF, ATTITUDE, LOCAL_POSITION,
                      GLOBAL_POSITION, LOCAL_ALTITUDE, MISSION, OFFBOARD_SIGNAL, HOME_POSITION, MANUAL_CONTROL,
                      GEOFENCE_MAX_DISTANCE, GEOFENCE_MAX_ALTITUDE, GEOFENCE_CUSTOM, NO_DATALINK, BATTERY_LOW,
                      BATTERY_CRITICAL, BATTERY_EMERGENCY)
