"""The PX4 events the emulator emits, each beside the STATUSTEXT PX4 sends with it (the '\\t'-terminated text).

PX4 calls mavlink_log_*("text\\t") and events::send(events::ID("name"), levels, "message", args...) side by side;
the emulator's commander and navigator say the text (a VehicleEvent with is_event True), and `to_px4_event` finds
the event PX4 sends with it: its name, message, argument types and levels as PX4's source states them, and the
argument values read back from the text. Sources: commander/Commander.cpp (arm, disarm, printRejectMode,
handle_command, landDetectorUpdate), navigator/mission_base.cpp (mission_execute, mission_finished*),
navigator/rtl_direct.cpp (vrtl_return_at, so spelled in PX4; rtl_land_at_destination, rtl_completed_loiter,
rtl_avoiding_geofence), navigator/navigator_main.cpp (rtl_avoidance_build_failed, rtl_destination_breaches),
commander/failsafe/framework.cpp (failsafe_rc_override: a pilot's takeover from a failsafe, an event only; without
a failsafe Commander::manualControlCheck's commander_rc_override with its STATUSTEXT), Commander::dataLinkCheck
(commander_gcs_lost, commander_dl_regained), navigator/takeoff.cpp
(navigator_takeoff_default_alt, whose altitude is read back from the text's one decimal;
navigator_takeoff_already_higher).

framework.cpp's warning-only battery failsafes (commander_failsafe_enter_low_bat, _crit_bat_warn,
_crit_low_bat_warn: events only, no STATUSTEXT) go with the texts commander/battery.py says for them.

The events no text tells are sent by the commander directly: the failsafe notices with their action and cause
(failsafe_notices.py) and the health and arming check report (health_events.py); DEFINITIONS lists all of them, so
the served metadata describes every event the emulator sends. A text no entry matches has no event.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache

from sitl_emu.events import enums, failsafe_notices, health_events
from sitl_emu.events.definition import EventDefinition, Px4Event, Values, critical, px4_event
from sitl_emu.events.library import Log
from sitl_emu.px4 import UI_NAMES, custom_mode
from sitl_emu.types import VehicleEvent

__all__ = ["DEFINITIONS", "ENTRIES", "EventDefinition", "Px4Event", "to_px4_event"]


@dataclass(frozen=True, slots=True)
class _Entry:
    definition: EventDefinition
    text: re.Pattern[str]
    values: Callable[[re.Match[str]], Values | None] = lambda m: ()
    statustext: bool | None = None  # matches only a text that does (True) / does not (False) go out as STATUSTEXT


def _reason(m: re.Match[str]) -> Values | None:
    value = enums.arm_disarm_reason(m.group(1))
    return None if value is None else (value,)


def _integers(m: re.Match[str]) -> Values:
    return tuple(int(g) for g in m.groups())


_NAV_BY_UI_NAME = {name: nav for nav, name in UI_NAMES.items()}


def _rejected_mode(m: re.Match[str]) -> Values | None:
    nav = _NAV_BY_UI_NAME.get(m.group(1))
    return None if nav is None else (custom_mode(nav), enums.navigation_mode(nav))


_REASON = enums.qualified(enums.ARM_DISARM_REASON)
_NAV_MODE = enums.qualified(enums.NAVIGATION_MODE)
_critical = critical


def _exact(text: str) -> re.Pattern[str]:
    return re.compile(re.escape(text))


ENTRIES: tuple[_Entry, ...] = (
    _Entry(EventDefinition("commander_armed_by", "Armed by {1}", (_REASON,)), re.compile(r"Armed by (.+)"), _reason),
    _Entry(EventDefinition("commander_disarmed_by", "Disarmed by {1}", (_REASON,)), re.compile(r"Disarmed by (.+)"),
           _reason),
    _Entry(_critical("commander_disarm_denied_not_landed", "Disarming denied: not landed"),
           _exact("Disarming denied: not landed")),
    _Entry(_critical("commander_arm_denied_resolve_failures", "Arming denied: Resolve system health failures first"),
           _exact("Arming denied: Resolve system health failures first")),
    _Entry(_critical("commander_modeswitch_not_avail", "Switching to mode '{2}' is currently not possible",
                     ("uint32_t", _NAV_MODE)),
           re.compile(r"Switching to (.+) is currently not available"), _rejected_mode),
    _Entry(EventDefinition("commander_rtl", "Returning to launch"), _exact("Returning to launch")),
    _Entry(EventDefinition("commander_landing_current_pos", "Landing at current position"),
           _exact("Landing at current position")),
    _Entry(_critical("commander_mission_start_denied_no_mission", "Mission start denied! No valid mission"),
           _exact("Mission start denied! No valid mission")),
    _Entry(EventDefinition("commander_landing_detected", "Landing detected"), _exact("Landing detected")),
    _Entry(EventDefinition("commander_takeoff_detected", "Takeoff detected"), _exact("Takeoff detected")),
    _Entry(EventDefinition("mission_execute", "Executing Mission"), _exact("Executing Mission")),
    _Entry(EventDefinition("mission_finished", "Mission finished, landed"), _exact("Mission finished, landed")),
    _Entry(EventDefinition("mission_finished_loiter", "Mission finished, loitering"),
           _exact("Mission finished, loitering")),
    _Entry(EventDefinition("vrtl_return_at", "RTL: start return at {1m_v} ({2m_v} above destination)",
                           ("int32_t", "int32_t")),
           re.compile(r"RTL: start return at (-?\d+) m \((-?\d+) m above destination\)"), _integers),
    _Entry(EventDefinition("navigator_takeoff_default_alt", "Using default takeoff altitude: {1:.2m}", ("float",)),
           re.compile(r"Using default takeoff altitude: (-?[\d.]+) m"), lambda m: (float(m.group(1)),)),
    _Entry(EventDefinition("navigator_takeoff_already_higher", "Already higher than takeoff altitude (not descending)",
                           external=Log.ERROR, internal=Log.INFO), _exact("Already higher than takeoff altitude")),
    _Entry(EventDefinition("commander_rc_override", "Pilot took over using sticks"),
           _exact("Pilot took over using sticks"), statustext=True),
    _Entry(EventDefinition("failsafe_rc_override", "Pilot took over using sticks"),
           _exact("Pilot took over using sticks"), statustext=False),
    _Entry(EventDefinition("commander_gcs_lost", "Connection to ground control station lost", (), Log.WARNING,
                           Log.INFO), _exact("Connection to ground station lost")),
    _Entry(EventDefinition("commander_dl_regained", "GCS connection regained"), _exact("GCS connection regained")),
    _Entry(EventDefinition("commander_failsafe_enter_low_bat", "Low battery level, return advised", (),
                           Log.WARNING, Log.INFO), _exact("Low battery level, return advised")),
    _Entry(EventDefinition("commander_failsafe_enter_crit_bat_warn", "Critical battery level, land now", (),
                           Log.CRITICAL, Log.INFO), _exact("Critical battery level, land now")),
    _Entry(EventDefinition("commander_failsafe_enter_crit_low_bat_warn", "Emergency battery level, land immediately",
                           (), Log.EMERGENCY, Log.INFO), _exact("Emergency battery level, land immediately")),
    _Entry(EventDefinition("rtl_land_at_destination", "RTL: land at destination"), _exact("RTL: land at destination")),
    _Entry(EventDefinition("rtl_completed_loiter", "RTL: completed, loitering"), _exact("RTL: completed, loitering")),
    _Entry(EventDefinition("rtl_avoiding_geofence", "RTL: avoiding geofence"), _exact("RTL: avoiding geofence")),
    _Entry(EventDefinition("rtl_avoidance_build_failed", "Geofence data invalid (code {1}), RTL will fly directly",
                           ("uint8_t",), external=Log.WARNING, internal=Log.INFO),
           re.compile(r"Geofence data invalid \(code (\d+)\), RTL will fly directly"), _integers),
    _Entry(EventDefinition("rtl_destination_breaches", "RTL destination breaches geofence, will fly directly",
                           external=Log.WARNING, internal=Log.INFO),
           _exact("RTL destination breaches geofence, will fly directly")),
)

DEFINITIONS: tuple[EventDefinition, ...] = (tuple(e.definition for e in ENTRIES) + failsafe_notices.DEFINITIONS
                                             + health_events.DEFINITIONS)


def to_px4_event(event: VehicleEvent) -> Px4Event | None:
    """The event PX4 sends with this text, or None (not an event, or none catalogued)."""
    if not event.is_event:
        return None
    found = _entry_for(event.text, event.statustext)
    if found is None:
        return None
    entry, match = found
    values = entry.values(match)
    if values is None:
        return None
    return px4_event(entry.definition, values, event.time_us)


@lru_cache(maxsize=256)
def _entry_for(text: str, statustext: bool) -> tuple[_Entry, re.Match[str]] | None:
    """The first entry whose pattern matches the whole text (and its STATUSTEXT condition), with the match: the
    patterns run once per distinct text (a vehicle says the same few texts again and again)."""
    for entry in ENTRIES:
        match = entry.text.fullmatch(text)
        if match is not None and entry.statustext in (None, statustext):
            return entry, match
    return None
