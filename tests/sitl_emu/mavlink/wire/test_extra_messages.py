"""The messages pymavlink lacks are framed as mavgen's generated code would (sitl_emu/mavlink/wire/extra_messages.py).

The CRC_EXTRA seed and wire order are computed from the field lists; the algorithm must reproduce every message
pymavlink has, and the seeds and payload lengths must be the published ones (MAVLINK_MSG_ID_<NAME>_CRC / _LEN of the
C headers generated from mavlink/mavlink).
"""

from __future__ import annotations

import re
from typing import Any

import pytest
from pymavlink.dialects.v20 import development as dialect

from sitl_emu.mavlink.wire import extra_messages as xm
from sitl_emu.mavlink.wire import fastpack

# (CRC_EXTRA, payload length) of the C headers generated from mavlink/mavlink's XML
PUBLISHED = {"LINK_NODE_STATUS": (117, 36), "ESC_INFO": (251, 46), "ESC_STATUS": (10, 57),
             "TIME_ESTIMATE_TO_TARGET": (232, 20), "ESTIMATOR_SENSOR_FUSION_STATUS": (197, 54),
             "COMPONENT_INFORMATION": (0, 212), "COMPONENT_METADATA": (182, 108), "EVENT": (160, 53),
             "CURRENT_EVENT_SEQUENCE": (106, 3), "REQUEST_EVENT": (33, 6), "RESPONSE_EVENT_ERROR": (77, 7)}


def _xml_fields(cls: Any) -> list[xm.Field]:
    lengths = dict(zip(cls.ordered_fieldnames, cls.array_lengths, strict=True))
    return [(name, ftype, lengths[name]) for name, ftype in zip(cls.fieldnames, cls.fieldtypes, strict=True)]


def _splits(cls: Any) -> list[list[xm.Field]]:
    """Candidate base-field lists, longest first: prefixes whose wire order, followed by the rest in XML order, is
    pymavlink's wire order (extension fields are appended unsorted; pymavlink does not say where they start)."""
    fields = _xml_fields(cls)
    out = []
    for k in range(len(fields), 0, -1):
        order = [f[0] for f in xm.wire_order(fields[:k])] + [f[0] for f in fields[k:]]
        if order == list(cls.ordered_fieldnames):
            out.append(fields[:k])
    return out


def _seed_and_layout_mismatch(cls: Any) -> str | None:
    seeds = {len(base): xm.crc_extra(cls.msgname, base) for base in _splits(cls)}
    if cls.crc_extra not in seeds.values():
        return f"{cls.msgname}: crc_extra {cls.crc_extra} not among {seeds}"
    fields = _xml_fields(cls)
    if seeds.get(len(fields)) == cls.crc_extra:  # no extensions: the struct layout is pymavlink's too
        ours = _expanded(xm.make_spec(cls.id, cls.msgname, fields).pack.__self__.format)
        if ours != _expanded(cls.unpacker.format):
            return f"{cls.msgname}: layout {ours}"
    return None


def test_crc_extra_algorithm_reproduces_every_pymavlink_message():
    table = sorted(dialect.mavlink_map.values(), key=lambda c: c.id)
    assert len(table) > 200
    assert [m for m in map(_seed_and_layout_mismatch, table) if m is not None] == []


def _expanded(fmt: str) -> list[str]:
    """A struct format as one code per item ("<B3f" -> B f f f; "<4s" -> 4s)."""
    out: list[str] = []
    for count, code in re.findall(r"(\d*)([a-zA-Z?])", fmt):
        out.extend([count + code] if code == "s" else [code] * int(count or 1))
    return out


@pytest.mark.parametrize("name", sorted(PUBLISHED))
def test_seeds_and_lengths_are_the_published_ones_and_pymavlink_has_none_of_them(name):
    spec = xm.SPECS[name]
    crc, length = PUBLISHED[name]
    assert spec.crc_extra == bytes((crc,))
    assert spec.pack.__self__.size == length
    assert spec.msg_id not in dialect.mavlink_map


def test_a_frame_carries_the_fields_in_wire_order_and_decodes_back():
    msg = xm.EXTRA.esc_status_encode(4, 123_456_789, [1, -2, 3, 6000], [11.5, 12.0, 12.5, 13.0], [0.0, 1.0, 2.0, 3.0])
    frame = fastpack.frame_message(msg, 7, 1, 1)
    assert frame[0] == 0xFD and frame[4:7] == bytes((7, 1, 1)) and int.from_bytes(frame[7:10], "little") == 291
    assert fastpack.x25_crc(frame[1:-2] + b"\x0a", 0xFFFF) == int.from_bytes(frame[-2:], "little")
    payload = frame[10:-2]
    assert payload[:8] == (123_456_789).to_bytes(8, "little")  # the uint64 first, the uint8 index last
    got = xm.decode(291, payload)
    assert got["index"] == 4 and got["rpm"] == [1, -2, 3, 6000]
    assert got["voltage"] == pytest.approx([11.5, 12.0, 12.5, 13.0])
    assert got["time_usec"] == 123_456_789


def test_pymavlink_parses_them_as_unknown_messages_without_error():
    frame = fastpack.frame_message(xm.EXTRA.link_node_status_encode(1, 0, 0, 2, 3, 0, 0, 0, 5, 6, 0), 0, 1, 1)
    parser = dialect.MAVLink(None)
    (msg,) = parser.parse_buffer(frame)
    assert msg.get_type() == "UNKNOWN_8"
