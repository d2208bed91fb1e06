"""The PX4 events the emulator emits, each beside the STATUSTEXT PX4 sends with it (the '\\t'-terminated text).

PX4 calls mavlink_log_*("text\\t") and events::send(events::ID("name"), levels, "message", args...) side by side;
the emulator's commander and navigator say the text (a VehicleEvent with is_event True), and `to_px4_event` finds
the event PX4 sends with it: its name, message, argument types and levels as PX4's source states them, and the
argument values read back from the text. Sources: commander/Commander.cpp (arm, disarm, printRejectMode,
handle_command, landDetectorUpdate), navigator/mission_base.cpp (mission_execute, mission_finished*),
navigator/rtl_direct.cpp (vrtl_return_at, so spelled in PX4; rtl_land_at_destination, rtl_completed_loiter,
rtl_avoiding_geofence), navigator/navigator_main.cpp (rtl_avoidance_build_failed, rtl_destination_breaches),
commander/failsafe/framework.cpp (failsafe_rc_override: a pilot's takeover), navigator/takeoff.cpp
(navigator_takeoff_default_alt, whose altitude is read back from the text's one decimal;
navigator_takeoff_already_higher).

A text no entry matches has no event here yet (the failsafe notices, which need the failsafe's cause and action);
its STATUSTEXT goes out as before.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass

from sitl_emu.events import enums
from sitl_emu.events.library import Log, event_id, log_levels, pack_arguments
from sitl_emu.px4 import UI_NAMES, custom_mode
from sitl_emu.types import VehicleEvent

Values = tuple[float, ...]


@dataclass(frozen=True, slots=True)
class EventDefinition:
    name: str  # events::ID("name")
    message: str  # libevents format: {1} is the first argument
    arguments: tuple[str, ...] = ()  # metadata types: a base type or "px4::<enum>"
    external: Log = Log.INFO
    internal: Log | None = None  # None: the same as external (events::send with one level)
    group: str = "default"

    @property
    def id(self) -> int:
        return event_id(self.name)

    @property
    def levels(self) -> int:
        return log_levels(self.external, self.internal)

    @property
    def base_types(self) -> tuple[str, ...]:
        by_name = {f"{enums.NAMESPACE}::{e.name}": e.base_type for e in enums.ENUMS}
        return tuple(by_name.get(t, t) for t in self.arguments)


@dataclass(frozen=True, slots=True)
class Px4Event:
    """One event as PX4's event_s holds it (what mavlink_events.cpp puts in an EVENT)."""

    id: int
    log_levels: int
    time_ms: int
    arguments: bytes  # 40 bytes


@dataclass(frozen=True, slots=True)
class _Entry:
    definition: EventDefinition
    text: re.Pattern[str]
    values: Callable[[re.Match[str]], Values | None] = lambda m: ()


def _reason(m: re.Match[str]) -> Values | None:
    value = enums.arm_disarm_reason(m.group(1))
    return None if value is None else (value,)


def _integers(m: re.Match[str]) -> Values:
    return tuple(int(g) for g in m.groups())


_NAV_BY_UI_NAME = {name: nav for nav, name in UI_NAMES.items()}


def _rejected_mode(m: re.Match[str]) -> Values | None:
    nav = _NAV_BY_UI_NAME.get(m.group(1))
    return None if nav is None else (custom_mode(nav), enums.navigation_mode(nav))


_REASON = f"{enums.NAMESPACE}::{enums.ARM_DISARM_REASON.name}"
_NAV_MODE = f"{enums.NAMESPACE}::{enums.NAVIGATION_MODE.name}"


def _critical(name: str, message: str, arguments: tuple[str, ...] = ()) -> EventDefinition:
    """{events::Log::Critical, events::LogInternal::Info}: PX4's refusals."""
    return EventDefinition(name, message, arguments, Log.CRITICAL, Log.INFO)


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
    _Entry(EventDefinition("failsafe_rc_override", "Pilot took over using sticks"),
           _exact("Pilot took over using sticks")),
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

DEFINITIONS: tuple[EventDefinition, ...] = tuple(e.definition for e in ENTRIES)


def to_px4_event(event: VehicleEvent) -> Px4Event | None:
    """The event PX4 sends with this text, or None (not an event, or none catalogued)."""
    if not event.is_event:
        return None
    for entry in ENTRIES:
        match = entry.text.fullmatch(event.text)
        if match is None:
            continue
        values = entry.values(match)
        if values is None:
            return None
        d = entry.definition
        return Px4Event(d.id, d.levels, event.time_us // 1000, pack_arguments(d.base_types, values))
    return None
