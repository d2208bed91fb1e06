"""PX4's events library: ids, log levels and arguments, as events::send() fills an event_s.

- An event's id (events::ID(name), px4_platform_common/events.h; Tools/px4events/srcparser.py computes the same for
  the metadata): the 32-bit FNV-1a hash of its name, cut to 24 bits, with the component id 1 (the autopilot) in the
  top byte. The metadata lists the event under component 1 by the lower 24 bits (its "sub id").
- log_levels: the internal level in the high nibble, the external one (what a ground station shows) in the low
  nibble; events::send with one level uses it for both (libevents' LogLevels).
- arguments: the values packed little endian one after the other in the order of the call, into 40 bytes.
"""

from __future__ import annotations

import struct
from enum import IntEnum
from functools import cache

FNV_OFFSET_BASIS = 0x811C9DC5
FNV_PRIME = 0x01000193
AUTOPILOT_COMPONENT = 1
MAX_ARGUMENTS_SIZE = 40

# argument types: libevents' base types -> struct code
BASE_TYPES: dict[str, str] = {
    "uint8_t": "B", "int8_t": "b", "uint16_t": "H", "int16_t": "h", "uint32_t": "I", "int32_t": "i",
    "uint64_t": "Q", "int64_t": "q", "float": "f",
}


class Log(IntEnum):
    """libevents' log levels (common/event_type.h), the same numbers as MAV_SEVERITY up to Debug."""

    EMERGENCY = 0
    ALERT = 1
    CRITICAL = 2
    ERROR = 3
    WARNING = 4
    NOTICE = 5
    INFO = 6
    DEBUG = 7
    PROTOCOL = 8
    DISABLED = 9


def hash_32_fnv1a(text: str) -> int:
    value = FNV_OFFSET_BASIS
    for byte in text.encode():
        value = ((value ^ byte) * FNV_PRIME) & 0xFFFFFFFF
    return value


@cache
def sub_id(name: str) -> int:
    """The lower 24 bits of the id: the key of the event in the metadata (worked out once per name: a vehicle sends
    the same few events again and again)."""
    return hash_32_fnv1a(name) & 0xFFFFFF


def event_id(name: str) -> int:
    """events::ID(name): the id an EVENT message carries."""
    return sub_id(name) | (AUTOPILOT_COMPONENT << 24)


def log_levels(external: Log, internal: Log | None = None) -> int:
    """The log_levels byte: internal << 4 | external (one level: both)."""
    return ((external if internal is None else internal) << 4) | external


def pack_arguments(base_types: tuple[str, ...], values: tuple[float, ...]) -> bytes:
    """The 40 argument bytes: each value as its base type, little endian, back to back, zero-filled."""
    return _packer(base_types).pack(*values).ljust(MAX_ARGUMENTS_SIZE, b"\0")


@cache
def _packer(base_types: tuple[str, ...]) -> struct.Struct:
    """The packer of these base types, made once per distinct list."""
    packer = struct.Struct("<" + "".join(BASE_TYPES[t] for t in base_types))
    if packer.size > MAX_ARGUMENTS_SIZE:
        raise ValueError(f"event arguments take {packer.size} bytes, more than {MAX_ARGUMENTS_SIZE}")
    return packer
