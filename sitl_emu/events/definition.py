"""One PX4 event as its source defines it (events::send(events::ID(name), levels, message, args...)) and as it goes
out (event_s: id, log levels, time, the 40 argument bytes); mavlink_events.cpp puts the latter in an EVENT.

An argument type is a libevents base type ("uint32_t") or one of PX4's enums ("px4::failsafe_action_t"), packed as
its base type. `group` and `type` are the metadata's: the health and arming check report's events are in the groups
"arming_check" and "health", its two summaries of type "summary" (Tools/px4events from the /* EVENT */ comments).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

from sitl_emu.events import enums
from sitl_emu.events.library import Log, event_id, log_levels, pack_arguments

Values = tuple[float, ...]

_BASE_OF = {enums.qualified(e): e.base_type for e in enums.ENUMS}


@dataclass(frozen=True, slots=True)
class EventDefinition:
    name: str  # events::ID("name")
    message: str  # libevents format: {1} is the first argument
    arguments: tuple[str, ...] = ()  # metadata types: a base type or "px4::<enum>"
    external: Log = Log.INFO
    internal: Log | None = None  # None: the same as external (events::send with one level)
    group: str = "default"
    type: str = ""  # "summary" for the report's summaries

    @property
    def id(self) -> int:
        return event_id(self.name)

    @property
    def levels(self) -> int:
        return log_levels(self.external, self.internal)

    @property
    def base_types(self) -> tuple[str, ...]:
        return _base_types(self.arguments)


@dataclass(frozen=True, slots=True)
class Px4Event:
    """One event as PX4's event_s holds it (what mavlink_events.cpp puts in an EVENT)."""

    id: int
    log_levels: int
    time_ms: int
    arguments: bytes  # 40 bytes


def px4_event(d: EventDefinition, values: Values, time_us: int, levels: int | None = None) -> Px4Event:
    """The event `d` sent now with these argument values (`levels`: other than the definition's, as a check event
    whose level depends on the situation)."""
    return Px4Event(d.id, d.levels if levels is None else levels, time_us // 1000, pack_arguments(d.base_types, values))


@cache
def _base_types(arguments: tuple[str, ...]) -> tuple[str, ...]:
    """Each argument's base type (an enum's is the enum's), worked out once per distinct list."""
    return tuple(_BASE_OF.get(t, t) for t in arguments)


def critical(name: str, message: str, arguments: tuple[str, ...] = ()) -> EventDefinition:
    """{events::Log::Critical, events::LogInternal::Info}: PX4's refusals."""
    return EventDefinition(name, message, arguments, Log.CRITICAL, Log.INFO)
