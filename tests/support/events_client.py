"""A ground station's side of PX4's events: libevents' ReceiveProtocol (libs/cpp/protocol/receive.h: follow the
sequence, ask for what was missed), its Parser (libs/python/libevents_parse/parser.py: find an event by component
and sub id in the metadata, unpack its arguments, fill the message) and its health and arming check report parser
(libs/python/libevents_parse/health_and_arming_checks.py, what QGroundControl's arming-check panel is built on),
written small for the tests.
"""

from __future__ import annotations

import re
import struct
from dataclasses import dataclass, field
from typing import Any

from sitl_emu.mavlink.wire import extra_messages as xm
from sitl_emu.mavlink.wire.fastpack import frame_message

EVENT, CURRENT_EVENT_SEQUENCE, RESPONSE_EVENT_ERROR = 410, 411, 413
_BASE = {"uint8_t": "B", "int8_t": "b", "uint16_t": "H", "int16_t": "h", "uint32_t": "I", "int32_t": "i",
         "uint64_t": "Q", "int64_t": "q", "float": "f"}


def extra_of(msg: Any) -> tuple[int, dict[str, Any]] | None:
    """(message id, fields) of a message pymavlink parsed as MAVLink_unknown, if extra_messages knows it."""
    name = msg.get_type()
    if not name.startswith("UNKNOWN_"):
        return None
    msg_id = int(name.removeprefix("UNKNOWN_"))
    if msg_id not in xm.MESSAGE_IDS:
        return None
    return msg_id, xm.decode(msg_id, xm.payload_of_unknown(bytes(msg.data)))


class EventsDecoder:
    """Decodes an EVENT with the events metadata (the JSON a component serves)."""

    def __init__(self, metadata: dict[str, Any]) -> None:
        assert metadata["version"] >= 1
        self.components = metadata["components"]

    def _find(self, event_id: int) -> tuple[dict[str, Any], tuple[str, dict[str, Any]]] | None:
        comp = self.components.get(str(event_id >> 24))
        if comp is None:
            return None
        for name, group in comp.get("event_groups", {}).items():
            event = group.get("events", {}).get(str(event_id & 0xFFFFFF))
            if event is not None:
                return comp, (name, event)
        return None

    def decode(self, event_id: int, arguments: bytes | list[int]) -> tuple[str, str] | None:
        """(name, message with its arguments filled in), or None for an event the metadata lacks."""
        parsed = self.parse(event_id, arguments)
        return None if parsed is None else (parsed.name, parsed.message)

    def parse(self, event_id: int, arguments: bytes | list[int], log_levels: int = 0) -> ParsedEvent | None:
        found = self._find(event_id)
        if found is None:
            return None
        comp, (group, event) = found[0], found[1]
        data, offset, values, kinds = bytes(arguments), 0, [], []
        for arg in event.get("arguments", []):
            enum = comp.get("enums", {}).get(arg["type"].split("::")[-1]) if "::" in arg["type"] else None
            code = _BASE[enum["type"] if enum else arg["type"]]
            (value,) = struct.unpack_from("<" + code, data, offset)
            offset += struct.calcsize(code)
            values.append(value)
            kinds.append(enum)
        shown = [_display(v, e) for v, e in zip(values, kinds, strict=True)]
        message = _ARGUMENT.sub(lambda m: _shown(m, shown), event["message"])
        return ParsedEvent(event_id, event["name"], message, group, event.get("type", ""), values, kinds, log_levels)


def _display(value: Any, enum: dict[str, Any] | None) -> Any:
    if enum is None:
        return value
    if enum.get("is_bitfield"):
        return ", ".join(e["description"] for k, e in enum["entries"].items() if value & int(k))
    return enum["entries"].get(str(value), {}).get("description", f"(unknown: {value})")


@dataclass
class ParsedEvent:
    id: int
    name: str
    message: str
    group: str
    type: str
    values: list[Any]
    enums: list[dict[str, Any] | None]
    log_levels: int = 0


# libevents' argument syntax: {N[:.DIGITS][UNIT]}, UNIT one of m, m_v (vertical metres: shown as m), m/s, m^2, C
_ARGUMENT = re.compile(r"\{(\d+)(?::(?:\.(\d+))?)?(m|m_v|m/s|m\^2|C)?\}")


def _shown(m: re.Match[str], values: list[Any]) -> str:
    value = values[int(m.group(1)) - 1]
    text = f"{value:.{m.group(2)}f}" if m.group(2) is not None else str(value)
    return text + ("" if m.group(3) is None else " " + ("m" if m.group(3) == "m_v" else m.group(3)))


class EventReceiver:
    """ReceiveProtocol for one vehicle component: in-order events, REQUEST_EVENT for gaps, errors counted."""

    def __init__(self, client: Any, target: tuple[int, int] = (1, 1)) -> None:
        self.client = client
        self.target = target
        self.latest: int | None = None
        self.current: int | None = None  # the newest sequence CURRENT_EVENT_SEQUENCE announced
        self.events: list[dict[str, Any]] = []
        self.lost = 0

    def feed(self, msgs: list[Any]) -> None:
        for msg in msgs:
            extra = extra_of(msg)
            if extra is None:
                continue
            msg_id, fields = extra
            if xm.source_of_unknown(bytes(msg.data)) != self.target:
                continue
            if msg_id == EVENT:
                self._event(fields)
            elif msg_id == CURRENT_EVENT_SEQUENCE:
                self._current(fields)
            elif msg_id == RESPONSE_EVENT_ERROR:
                self._error(fields)

    def _event(self, e: dict[str, Any]) -> None:
        if self.latest is None:
            self.latest = (e["sequence"] - 1) & 0xFFFF
        diff = (e["sequence"] - self.latest - 1) & 0xFFFF
        if diff > 0x7FFF:  # older: a duplicate
            return
        if diff > 0:  # we missed some: ask for the next one
            self.request((self.latest + 1) & 0xFFFF)
            return
        self.latest = e["sequence"]
        self.events.append(e)
        if self.current is not None and 0 < (self.current - self.latest) & 0xFFFF <= 0x7FFF:
            self.request((self.latest + 1) & 0xFFFF)  # more announced than received: the next one

    def _current(self, c: dict[str, Any]) -> None:
        if c["flags"] & 1 or self.latest is None:
            self.latest = c["sequence"]
        elif 0 < (c["sequence"] - self.latest) & 0xFFFF <= 0x7FFF:
            self.request((self.latest + 1) & 0xFFFF)
        self.current = c["sequence"]

    def _error(self, err: dict[str, Any]) -> None:
        ours = (self.client.mav.srcSystem, self.client.mav.srcComponent)
        if (err["target_system"], err["target_component"]) != ours:
            return
        if self.latest is None or err["sequence"] != (self.latest + 1) & 0xFFFF:
            return
        self.lost += (err["sequence_oldest_available"] - self.latest - 1) & 0xFFFF
        self.latest = (err["sequence_oldest_available"] - 1) & 0xFFFF
        self.request((self.latest + 1) & 0xFFFF)

    def request(self, first: int, last: int | None = None) -> None:
        msg = xm.EXTRA.request_event_encode(self.target[0], self.target[1], first, first if last is None else last)
        self.client.send_raw(frame_message(msg, self.client.mav.seq, self.client.mav.srcSystem,
                                           self.client.mav.srcComponent))
        self.client.mav.seq = (self.client.mav.seq + 1) % 256


@dataclass
class HealthResults:
    """libevents' HealthAndArmingChecks.Results: per mode group (bit index) can_arm / can_run, per health component
    its flags, and the checks (message, affected modes, health component index, external log level)."""

    can_arm: dict[int, bool] = field(default_factory=dict)
    can_run: dict[int, bool] = field(default_factory=dict)
    components: dict[str, dict[str, bool]] = field(default_factory=dict)
    checks: list[tuple[str, int, int, int]] = field(default_factory=list)

    def checks_for(self, group: int) -> list[str]:
        """The messages of the checks that affect a mode group (what QGC lists for the current mode)."""
        return [message for message, modes, _, _ in self.checks if modes >> group & 1]


class HealthAndArmingChecks:
    """libevents' parser: an arming_check summary, the checks, then the health summary of the same chunk."""

    def __init__(self) -> None:
        self.results: HealthResults | None = None
        self._current: HealthResults | None = None

    def handle(self, e: ParsedEvent) -> bool:
        """Feed one event; True when a whole report was read (self.results)."""
        if e.group == "arming_check" and e.type == "summary" and len(e.values) >= 5:
            self._current = self._summary(e)
        elif e.group in ("arming_check", "health") and e.type == "" and self._current is not None:
            self._current.checks.append((e.message, e.values[0], e.values[1], e.log_levels & 0xF))
        elif e.group == "health" and e.type == "summary" and self._current is not None and e.values[0] == 0:
            for _name, bit, flags in self._entries(e.enums[1]):
                flags.update(present=bool(e.values[1] & bit), error=bool(e.values[2] & bit),
                             warning=bool(e.values[3] & bit))
            self.results, self._current = self._current, None
            return True
        return False

    def _summary(self, e: ParsedEvent) -> HealthResults:
        r = HealthResults()
        assert e.enums[3] is not None and e.enums[1] is not None
        for key in e.enums[3]["entries"]:
            index = int(key).bit_length() - 1
            r.can_arm[index], r.can_run[index] = bool(e.values[3] & int(key)), bool(e.values[4] & int(key))
        for key, entry in e.enums[1]["entries"].items():
            r.components[entry["name"]] = {"arm_error": bool(e.values[1] & int(key)),
                                           "arm_warning": bool(e.values[2] & int(key))}
        return r

    def _entries(self, enum: dict[str, Any] | None) -> list[tuple[str, int, dict[str, bool]]]:
        assert enum is not None and self._current is not None
        return [(entry["name"], int(key), self._current.components.setdefault(entry["name"], {}))
                for key, entry in enum["entries"].items()]
