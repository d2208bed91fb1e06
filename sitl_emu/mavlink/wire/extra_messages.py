"""Messages PX4 streams that pymavlink's bundled dialects (2.4.x) do not define, framed like fastpack's own.

PX4 builds against a newer MAVLink (mavlink/mavlink message_definitions common.xml / development.xml) than the one
pymavlink bundles; these are the messages of the ground-station stream set (../shared/reference/px4-gcs-streams.json)
it lacks. Each is described here by its fields in XML order (name, MAVLink type, array length); from that we get what
mavgen would: the wire order (fields sorted by type size, largest first, stable), the struct layout and the
CRC_EXTRA seed (x25 checksum over "NAME " and each wire-ordered field's "type name " plus its array length).
tests/sitl_emu/mavlink/wire/test_extra_messages.py checks the seed algorithm against every pymavlink message and the
seeds below against the published MAVLINK_MSG_ID_<NAME>_CRC values.

`EXTRA.<name>_encode(...)` takes the fields in XML order (arrays as sequences) and returns a fastpack `Packed`, which
Endpoint.send() frames as any other. A pymavlink client parses these as MAVLink_unknown ("UNKNOWN_290"), exactly as
it parses them from PX4.

Also here: the events protocol (EVENT, CURRENT_EVENT_SEQUENCE, REQUEST_EVENT, RESPONSE_EVENT_ERROR: the emulator
speaks it, sitl_emu/mavlink/protocols/events.py) and component metadata (COMPONENT_METADATA and the older
COMPONENT_INFORMATION), which pymavlink 2.4 lacks too; a REQUEST_EVENT arrives as pymavlink's MAVLink_unknown
("UNKNOWN_412"), whose payload `payload_of_unknown` cuts out for `decode`.
"""

from __future__ import annotations

import struct
from collections.abc import Callable, Sequence
from typing import Any

from sitl_emu.mavlink.wire.fastpack import MessageSpec, Packed, x25_crc

# MAVLink type -> (struct code, size in bytes)
_TYPES: dict[str, tuple[str, int]] = {
    "uint64_t": ("Q", 8), "int64_t": ("q", 8), "double": ("d", 8),
    "uint32_t": ("I", 4), "int32_t": ("i", 4), "float": ("f", 4),
    "uint16_t": ("H", 2), "int16_t": ("h", 2),
    "uint8_t": ("B", 1), "int8_t": ("b", 1), "char": ("s", 1),
}

Field = tuple[str, str, int]  # name, MAVLink type, array length (0: scalar)


def wire_order(fields: Sequence[Field]) -> list[Field]:
    """mavgen's field order on the wire: by type size, largest first; equal sizes keep their XML order."""
    return sorted(fields, key=lambda f: -_TYPES[f[1]][1])


def crc_extra(name: str, fields: Sequence[Field]) -> int:
    """mavgen's CRC_EXTRA seed of a message without extension fields."""
    text = bytearray(f"{name} ".encode())
    for fname, ftype, length in wire_order(fields):
        text += f"{ftype} {fname} ".encode()
        if length:
            text.append(length)
    crc = x25_crc(bytes(text), 0xFFFF)
    return (crc & 0xFF) ^ (crc >> 8)


def _code(mav_type: str, length: int) -> str:
    """The struct code of one field: a char array is one bytes item, any other array one item per element."""
    code = _TYPES[mav_type][0]
    return f"{max(length, 1)}s" if mav_type == "char" else code * max(length, 1)


def make_spec(msg_id: int, name: str, fields: Sequence[Field]) -> MessageSpec:
    """A fastpack spec whose encode takes the fields in XML order (arrays as sequences), no defaults."""
    wire = wire_order(fields)
    layout = struct.Struct("<" + "".join(_code(t, length) for _, t, length in wire))
    position = {f[0]: i for i, f in enumerate(fields)}
    terms = tuple((position[fname], length if ftype != "char" else 0) for fname, ftype, length in wire)
    return MessageSpec(msg_id, name, bytes((crc_extra(name, fields),)), layout.pack, len(fields), (), terms)


# Field lists in XML order, from mavlink/mavlink message_definitions (common.xml, development.xml).
_DEFINITIONS: dict[str, tuple[int, tuple[Field, ...]]] = {
    "LINK_NODE_STATUS": (8, (
        ("timestamp", "uint64_t", 0), ("tx_buf", "uint8_t", 0), ("rx_buf", "uint8_t", 0),
        ("tx_rate", "uint32_t", 0), ("rx_rate", "uint32_t", 0), ("rx_parse_err", "uint16_t", 0),
        ("tx_overflows", "uint16_t", 0), ("rx_overflows", "uint16_t", 0), ("messages_sent", "uint32_t", 0),
        ("messages_received", "uint32_t", 0), ("messages_lost", "uint32_t", 0))),
    "ESC_INFO": (290, (
        ("index", "uint8_t", 0), ("time_usec", "uint64_t", 0), ("counter", "uint16_t", 0), ("count", "uint8_t", 0),
        ("connection_type", "uint8_t", 0), ("info", "uint8_t", 0), ("failure_flags", "uint16_t", 4),
        ("error_count", "uint32_t", 4), ("temperature", "int16_t", 4))),
    "ESC_STATUS": (291, (
        ("index", "uint8_t", 0), ("time_usec", "uint64_t", 0), ("rpm", "int32_t", 4), ("voltage", "float", 4),
        ("current", "float", 4))),
    "TIME_ESTIMATE_TO_TARGET": (380, (
        ("safe_return", "int32_t", 0), ("land", "int32_t", 0), ("mission_next_item", "int32_t", 0),
        ("mission_end", "int32_t", 0), ("commanded_action", "int32_t", 0))),
    "ESTIMATOR_SENSOR_FUSION_STATUS": (514, (
        ("intended", "uint8_t", 9), ("active", "uint8_t", 9), ("test_ratio", "float", 9))),
    "COMPONENT_INFORMATION": (395, (
        ("time_boot_ms", "uint32_t", 0), ("general_metadata_file_crc", "uint32_t", 0),
        ("general_metadata_uri", "char", 100), ("peripherals_metadata_file_crc", "uint32_t", 0),
        ("peripherals_metadata_uri", "char", 100))),
    "COMPONENT_METADATA": (397, (
        ("time_boot_ms", "uint32_t", 0), ("file_crc", "uint32_t", 0), ("uri", "char", 100))),
    "EVENT": (410, (
        ("destination_component", "uint8_t", 0), ("destination_system", "uint8_t", 0), ("id", "uint32_t", 0),
        ("event_time_boot_ms", "uint32_t", 0), ("sequence", "uint16_t", 0), ("log_levels", "uint8_t", 0),
        ("arguments", "uint8_t", 40))),
    "CURRENT_EVENT_SEQUENCE": (411, (("sequence", "uint16_t", 0), ("flags", "uint8_t", 0))),
    "REQUEST_EVENT": (412, (
        ("target_system", "uint8_t", 0), ("target_component", "uint8_t", 0), ("first_sequence", "uint16_t", 0),
        ("last_sequence", "uint16_t", 0))),
    "RESPONSE_EVENT_ERROR": (413, (
        ("target_system", "uint8_t", 0), ("target_component", "uint8_t", 0), ("sequence", "uint16_t", 0),
        ("sequence_oldest_available", "uint16_t", 0), ("reason", "uint8_t", 0))),
}

SPECS: dict[str, MessageSpec] = {name: make_spec(msg_id, name, fields)
                                 for name, (msg_id, fields) in _DEFINITIONS.items()}
MESSAGE_IDS: frozenset[int] = frozenset(spec.msg_id for spec in SPECS.values())
NAMES: dict[int, str] = {spec.msg_id: name for name, spec in SPECS.items()}


def fields_of(name: str) -> tuple[Field, ...]:
    return _DEFINITIONS[name][1]


def decode(msg_id: int, payload: bytes) -> dict[str, Any]:
    """A received payload (MAVLink 2 may have cut its trailing zeros) as {field: value}, arrays as lists."""
    name = NAMES[msg_id]
    layout = struct.Struct("<" + "".join(_code(t, length) for _, t, length in wire_order(fields_of(name))))
    values = list(layout.unpack(payload.ljust(layout.size, b"\0")[:layout.size]))
    out: dict[str, Any] = {}
    for fname, ftype, length in wire_order(fields_of(name)):
        count = 1 if not length or ftype == "char" else length
        taken, values = values[:count], values[count:]
        out[fname] = taken if length and ftype != "char" else taken[0]
    return out


def payload_of_unknown(frame: bytes) -> bytes:
    """The payload of a whole frame as pymavlink's MAVLink_unknown keeps it (`.data`): after the 10-byte MAVLink 2
    header or the 6-byte MAVLink 1 header, as long as the length byte says."""
    header = 10 if frame[:1] == b"\xfd" else 6
    return bytes(frame[header:header + frame[1]])


def source_of_unknown(frame: bytes) -> tuple[int, int]:
    """(sysid, compid) from a whole frame's header (pymavlink leaves an unknown message's source unset)."""
    at = 5 if frame[:1] == b"\xfd" else 3
    return frame[at], frame[at + 1]


class ExtraEncoder:
    """`EXTRA.esc_status_encode(index, time_usec, rpm, voltage, current)`: fields in XML order -> Packed."""

    def __init__(self, specs: dict[str, MessageSpec]) -> None:
        for name, spec in specs.items():
            setattr(self, f"{name.lower()}_encode", spec.encode)

    def __getattr__(self, attr: str) -> Callable[..., Packed]:  # for mypy: the attributes set above
        raise AttributeError(attr)


EXTRA = ExtraEncoder(SPECS)
