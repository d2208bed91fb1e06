"""The ULog file format, as bytes: what PX4's logger writes, one message at a time (no I/O, no clock here).

Sources: PX4 src/modules/logger/messages.h (the message layouts, packed, little endian), logger.cpp (write_header,
write_info, write_formats, write_parameters, the 'L' and 'S' messages of its main loop) and the ULog file format
page of PX4's documentation. A file is the 16-byte header (magic "ULog", 0x01 0x12 0x35, format version 1, the
start time in µs), then messages, each a 3-byte header (uint16 size of what follows, uint8 type) and its body:
- 'B' flag bits, right after the header: 8 compat bytes (PX4 sets bit 0, "default parameters present"), 8 incompat
  bytes (0: nothing appended), 3 uint64 appended offsets (0);
- 'F' a format "name:type field;type field;...", with PX4's `_paddingN` byte fields where its structs have padding;
- 'I' an info (key length, "type name", value), 'P' a parameter, 'Q' a parameter default (its kinds bits first);
- 'A' subscribe a message id to a format (multi_id, msg_id, name), 'D' data (msg_id, the struct's bytes);
- 'L' a logged string: level as the ASCII digit of the syslog level (PX4 writes `severity + '0'`), timestamp, text;
- 'S' sync: 8 magic bytes PX4 writes every 500 ms so a reader can find its way after corruption.

pyulog's own writer writes a whole parsed log at once; a flight log is written while the vehicle flies, so the
messages are built here one by one.
"""

from __future__ import annotations

import operator
import struct
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Final

HEADER_MAGIC: Final = b"ULog\x01\x12\x35"
FILE_VERSION: Final = 1
SYNC_MAGIC = bytes((0x2F, 0x73, 0x13, 0x20, 0x25, 0x0C, 0xBB, 0x12))
COMPAT_DEFAULT_PARAMETERS: Final = 1  # ULOG_COMPAT_FLAG0_DEFAULT_PARAMETERS_MASK
DEFAULT_SYSTEM: Final = 1  # ulog_parameter_default_type_t::system
DEFAULT_CURRENT_SETUP: Final = 2  # ulog_parameter_default_type_t::current_setup
MAX_TEXT: Final = 127  # ulog_message_logging_s.message is 128 chars, NUL included

# C type -> struct code (ULog's basic types)
STRUCT_CODES = {
    "int8_t": "b", "uint8_t": "B", "int16_t": "h", "uint16_t": "H", "int32_t": "i", "uint32_t": "I",
    "int64_t": "q", "uint64_t": "Q", "float": "f", "double": "d", "bool": "?", "char": "c",
}
_HEAD = struct.Struct("<HB")
_TIMESTAMP = struct.Struct("<Q")
_DATA_ID = struct.Struct("<H")
_LOGGING = struct.Struct("<BQ")
_ADD_LOGGED = struct.Struct("<BH")


@dataclass(frozen=True, slots=True)
class Field:
    ctype: str
    name: str
    count: int = 0  # 0: a scalar; N: an array of N


def parse_fields(spec: str) -> list[Field]:
    """"uint64_t timestamp;float[3] xyz;uint8_t[4] _padding0" -> Fields (a trailing ';' is allowed)."""
    fields = []
    for item in filter(None, (s.strip() for s in spec.split(";"))):
        ctype, _, name = item.partition(" ")
        count = 0
        if ctype.endswith("]"):
            ctype, _, size = ctype[:-1].partition("[")
            count = int(size)
        if ctype not in STRUCT_CODES or not name:
            raise ValueError(f"not a ULog field: {item!r}")
        fields.append(Field(ctype, name, count))
    return fields


class MessageFormat:
    """One topic's format: its 'F' text, its fields and their defaults (a DataPacker writes its 'D' messages).

    A field without a default is zero (PX4's structs are zero-initialised); padding is zero bytes.
    """

    def __init__(self, name: str, spec: str) -> None:
        self.name = name
        self.fields = parse_fields(spec)
        codes = []
        self._slots: dict[str, tuple[int, int]] = {}  # name -> (index in the values, count or 0)
        defaults: list[Any] = []
        for f in self.fields:
            n = max(f.count, 1)
            if f.name.startswith("_padding"):
                codes.append(f"{n}x")
                continue
            codes.append(f"{f.count}{STRUCT_CODES[f.ctype]}" if f.count else STRUCT_CODES[f.ctype])
            self._slots[f.name] = (len(defaults), f.count)
            zero: Any = False if f.ctype == "bool" else 0
            defaults.extend([zero] * n)
        while codes and codes[-1].endswith("x"):  # PX4 writes a topic without its trailing padding
            codes.pop()  # (logger.cpp: o_size_no_padding)
        self.written_codes = codes  # the struct code of each field written (trailing padding not)
        self._struct = struct.Struct("<" + "".join(codes))
        self._defaults = defaults

    @property
    def size(self) -> int:
        """The bytes of its 'D' data: the struct without its trailing padding."""
        return self._struct.size

    def text(self) -> str:
        """The body of its 'F' message, as PX4 writes it (each field followed by ';')."""
        parts = [f"{f.ctype}[{f.count}] {f.name};" if f.count else f"{f.ctype} {f.name};" for f in self.fields]
        return f"{self.name}:" + "".join(parts)

    def set_defaults(self, values: Mapping[str, Any]) -> None:
        """Values of the fields a DataPacker is not given (fields that never change); the others default to zero."""
        self._defaults = self._filled(values)

    def default_bytes(self, index: int) -> bytes:
        """The bytes of written field `index` (of `fields`) with its default value (padding: zero bytes)."""
        field, code = self.fields[index], self.written_codes[index]
        if field.name not in self._slots:
            return struct.pack("<" + code)
        start, count = self._slots[field.name]
        return struct.pack("<" + code, *self._defaults[start:start + max(count, 1)])

    def _filled(self, values: Mapping[str, Any]) -> list[Any]:
        out = self._defaults.copy()
        slots = self._slots
        for name, value in values.items():
            index, count = slots[name]
            if count:
                out[index:index + count] = value
            else:
                out[index] = value
        return out


class DataPacker:
    """A topic's 'D' messages as `msg_id`, from the values of the fields `names`: a flat tuple, in the order of
    `names`, an array's elements in place of the array ((t, t, *q) for "timestamp", "timestamp_sample", "q"). A
    message is the 3-byte header, msg_id, then every field in the format's order: a field not in `names` has its
    default (MessageFormat.set_defaults, else zero), padding is zero bytes, the trailing padding is not written.

    The work is done once, here: the message header becomes constant bytes, and one struct packs the body, in
    which each run of fields not in `names` is a pad (no argument) when its bytes are all zero and a constant
    `Ns` argument otherwise. When `names` follow the format's order and no run needs an argument, the values are
    packed as they come; else they are gathered first, with the constants, into the struct's order.
    """

    def __init__(self, fmt: MessageFormat, msg_id: int, names: Sequence[str]) -> None:
        counts = {f.name: max(f.count, 1) for f in fmt.fields if not f.name.startswith("_padding")}
        unknown = set(names) - set(counts)
        if unknown or len(set(names)) != len(names):
            raise ValueError(f"{fmt.name}: fields {sorted(unknown)} unknown or named twice in {list(names)}")
        starts = {}  # name -> index of its first value
        self._count = 0  # how many values a message takes
        for name in names:
            starts[name], self._count = self._count, self._count + counts[name]
        codes: list[str] = []
        sources: list[int] = []  # per struct argument: its index in values + constants
        constants: list[bytes] = []

        def add_defaults(run: bytes) -> None:
            if not run:
                return
            if not any(run):
                codes.append(f"{len(run)}x")
            else:
                codes.append(f"{len(run)}s")
                sources.append(self._count + len(constants))
                constants.append(run)

        run = b""
        for i, code in enumerate(fmt.written_codes):
            name = fmt.fields[i].name
            if name not in starts:
                run += fmt.default_bytes(i)
                continue
            add_defaults(run)
            run = b""
            codes.append(code)
            sources.extend(range(starts[name], starts[name] + counts[name]))
        add_defaults(run)
        self._head = _HEAD.pack(_DATA_ID.size + fmt.size, ord("D")) + _DATA_ID.pack(msg_id)
        self._pack = struct.Struct("<" + "".join(codes)).pack
        self._constants = tuple(constants)
        in_order = sources == list(range(self._count))
        self._gather: Callable[[tuple[Any, ...]], tuple[Any, ...]] | None = \
            None if in_order else operator.itemgetter(*sources)  # (not in order: 2 sources at least)

    def __call__(self, values: tuple[Any, ...]) -> bytes:
        if len(values) != self._count:
            raise ValueError(f"{len(values)} values for {self._count}")
        if self._gather is not None:
            values = self._gather(values + self._constants)
        pack = self._pack  # (compiled, a starred call of an attribute would look the attribute up by name)
        return self._head + pack(*values)


def message(kind: bytes, body: bytes) -> bytes:
    """One message: its 3-byte header, then `body`."""
    return _HEAD.pack(len(body), kind[0]) + body


def file_header(timestamp_us: int) -> bytes:
    return HEADER_MAGIC + bytes((FILE_VERSION,)) + _TIMESTAMP.pack(timestamp_us)


def flag_bits() -> bytes:
    compat = bytes((COMPAT_DEFAULT_PARAMETERS,)) + bytes(7)
    return message(b"B", compat + bytes(8) + bytes(24))


def format_definition(fmt: MessageFormat) -> bytes:
    return message(b"F", fmt.text().encode())


def _key_value(key: str, value: bytes) -> bytes:
    k = key.encode()
    return bytes((len(k),)) + k + value


def info(name: str, value: str | int, ctype: str = "") -> bytes:
    """An 'I' message: a string (char[len]) or an integer of `ctype` (PX4 writes int32_t, uint32_t, uint64_t)."""
    if isinstance(value, str):
        data = value.encode()
        return message(b"I", _key_value(f"char[{len(data)}] {name}", data))
    ctype = ctype or "int32_t"
    return message(b"I", _key_value(f"{ctype} {name}", struct.pack("<" + STRUCT_CODES[ctype], value)))


def _param_body(name: str, value: float, is_int: bool) -> bytes:
    if is_int:
        return _key_value(f"int32_t {name}", struct.pack("<i", int(value)))
    return _key_value(f"float {name}", struct.pack("<f", float(value)))


def parameter(name: str, value: float, is_int: bool) -> bytes:
    return message(b"P", _param_body(name, value, is_int))


def parameter_default(name: str, value: float, is_int: bool, kinds: int = DEFAULT_SYSTEM) -> bytes:
    return message(b"Q", bytes((kinds,)) + _param_body(name, value, is_int))


def add_logged(msg_id: int, name: str, multi_id: int = 0) -> bytes:
    return message(b"A", _ADD_LOGGED.pack(multi_id, msg_id) + name.encode())


def log_text(level: int, timestamp_us: int, text: str) -> bytes:
    """An 'L' message; `level` 0 (emergency) .. 7 (debug), MAVLink's severities; longer texts are cut as PX4's."""
    body = text.encode()[:MAX_TEXT]
    return message(b"L", _LOGGING.pack(ord("0") + level, timestamp_us) + body)


def sync() -> bytes:
    return message(b"S", SYNC_MAGIC)


def formats_and_subscriptions(formats: Sequence[MessageFormat]) -> tuple[bytes, bytes]:
    """The 'F' messages of `formats`, and an 'A' per format with msg_id its place in the sequence."""
    defs = b"".join(format_definition(f) for f in formats)
    subs = b"".join(add_logged(i, f.name) for i, f in enumerate(formats))
    return defs, subs
