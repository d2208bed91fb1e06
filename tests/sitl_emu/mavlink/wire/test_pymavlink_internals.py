"""What fastpack reads of pymavlink is still there, in the shape it expects (sitl_emu/mavlink/wire/fastpack.py).

fastpack builds every frame from pymavlink's generated message classes and encode functions, which are pymavlink's
internals rather than its documented API. pyproject.toml bounds pymavlink to the newest version checked; before
raising that bound, this file (with test_fastpack.py's byte-for-byte comparisons) must pass on the new version.
"""

from __future__ import annotations

import importlib.metadata
import inspect
import re
import struct
from typing import Any

from pymavlink.dialects.v20 import development as dialect
from support import REPO_ROOT

from sitl_emu.mavlink.version import ProtocolVersionMessage
from sitl_emu.mavlink.wire import fastpack

MAVLINK_TYPES = {"char", "int8_t", "uint8_t", "int16_t", "uint16_t", "int32_t", "uint32_t", "float", "int64_t",
                 "uint64_t", "double"}
STRUCT_CODES = {"char": "s", "int8_t": "b", "uint8_t": "B", "int16_t": "h", "uint16_t": "H", "int32_t": "i",
                "uint32_t": "I", "float": "f", "int64_t": "q", "uint64_t": "Q", "double": "d"}


def _shape_problems(cls: Any) -> list[str]:
    """How a generated message class differs from what fastpack reads: the class attributes, their types and how
    they agree with each other and with the class's struct."""
    problems = []
    name = cls.msgname
    if dialect.__dict__.get(f"MAVLink_{name.lower()}_message") is not cls:
        problems.append("not found as MAVLink_<name>_message")
    if not (isinstance(cls.id, int) and dialect.mavlink_map.get(cls.id) is cls):
        problems.append("id")
    if not (isinstance(cls.crc_extra, int) and 0 <= cls.crc_extra < 256):
        problems.append("crc_extra")
    fields, types, ordered, arrays = cls.fieldnames, cls.fieldtypes, cls.ordered_fieldnames, cls.array_lengths
    if not (len(fields) == len(types) == len(ordered) == len(arrays) and sorted(fields) == sorted(ordered)):
        return [*problems, "fieldnames / fieldtypes / ordered_fieldnames / array_lengths disagree"]
    if not set(types) <= MAVLINK_TYPES or not all(isinstance(n, int) and n >= 0 for n in arrays):
        problems.append("field types or array lengths")
    if not isinstance(cls.unpacker, struct.Struct):
        return [*problems, "unpacker is not a struct.Struct"]
    kind = dict(zip(fields, types, strict=True))
    expected = "<" + "".join(f"{n}s" if kind[f] == "char" and n else STRUCT_CODES[kind[f]] * max(n, 1)
                             for f, n in zip(ordered, arrays, strict=True))
    if _codes(cls.unpacker.format) != _codes(expected):
        problems.append(f"unpacker {cls.unpacker.format} is not the wire order {expected}")
    encode = getattr(dialect.MAVLink, f"{name.lower()}_encode", None)
    if encode is None or list(inspect.signature(encode).parameters)[1:] != list(fields):
        problems.append("MAVLink.<name>_encode does not take the fields in order")
    return problems


def _codes(fmt: str) -> list[str]:
    """A struct format as one code per item ("<B3f" -> B f f f; "<4s" -> 4s)."""
    out: list[str] = []
    for count, code in re.findall(r"(\d*)([a-zA-Z?])", fmt):
        out.extend([count + code] if code == "s" else [code] * int(count or 1))
    return out


def test_every_message_class_has_the_shape_fastpack_reads():
    # (test_commands_wire.py adds the emulator's PROTOCOL_VERSION to the map for its client: not pymavlink's)
    table = [cls for cls in dialect.mavlink_map.values() if cls is not ProtocolVersionMessage]
    assert len(table) > 200
    broken = {cls.msgname: p for cls in table if (p := _shape_problems(cls))}
    assert broken == {}


def test_the_dialect_and_its_encoder_are_where_fastpack_finds_them():
    assert dialect.MAVLink.heartbeat_encode.__defaults__ == (3,)  # mavlink_version: an encode default fastpack copies
    assert fastpack.ENCODER.heartbeat_encode(6, 8, 0, 0, 0).values[-1] == 3
    assert callable(dialect.x25crc) and dialect.x25crc(b"123456789").crc == 0x6F91  # CRC-16/MCRF4XX check value


def test_pyproject_bounds_pymavlink_to_a_checked_version():
    """The installed pymavlink (the one these tests ran on) is within the bound; the bound is an inclusive one."""
    requirement = re.search(r'"(pymavlink[^"]*)"', (REPO_ROOT / "pyproject.toml").read_text())
    assert requirement is not None
    upper = re.search(r"<=\s*([\d.]+)", requirement.group(1))
    assert upper is not None, f"{requirement.group(1)}: no upper bound"
    installed = tuple(int(p) for p in importlib.metadata.version("pymavlink").split(".")[:3])
    assert installed <= tuple(int(p) for p in upper.group(1).split("."))
