"""The scripted clients' parser (sitl_emu/testing/frames.py) decodes only the messages asked for, and those exactly as
pymavlink alone would: checksum and all. FlightClient decodes only what it reads (issue 28)."""

from __future__ import annotations

from typing import Any

import pytest
from pymavlink.dialects.v20 import development as dialect

from sitl_emu.runtime.swarm import DEFAULT_HOME
from sitl_emu.testing.client import OBSERVED, FlightClient
from sitl_emu.testing.frames import MessageFilter, message_id
from sitl_emu.testing.sim import Sim

SIGNING_KEY = bytes(range(32))


def _frames() -> list[bytes]:
    """One frame each: MAVLink 2 heartbeat, attitude, a statustext, a signed heartbeat, a MAVLink 1 heartbeat."""
    mav = dialect.MAVLink(None, srcSystem=1, srcComponent=1)
    out = [mav.heartbeat_encode(2, 12, 0, 0, 3).pack(mav), mav.attitude_encode(10, 0.1, 0.2, 0.3, 0, 0, 0).pack(mav),
           mav.statustext_encode(6, b"hello", 0, 0).pack(mav)]
    signer = dialect.MAVLink(None, srcSystem=1, srcComponent=1)
    signer.signing.secret_key = SIGNING_KEY
    signer.signing.sign_outgoing = True
    out.append(signer.heartbeat_encode(2, 12, 0, 0, 4).pack(signer))
    v1 = dialect.MAVLink(None, srcSystem=1, srcComponent=1)
    v1.WIRE_PROTOCOL_VERSION = "1.0"
    out.append(v1.heartbeat_encode(2, 12, 0, 0, 5).pack(v1, force_mavlink1=True))
    return out


def _pymavlink(data: bytes) -> list[Any]:
    parser = dialect.MAVLink(None)
    parser.robust_parsing = True
    return parser.parse_buffer(data) or []


def test_wanted_messages_come_out_as_pymavlink_gives_them_and_the_others_are_skipped():
    wanted = MessageFilter(("HEARTBEAT", "STATUSTEXT"))
    got = [m for frame in _frames() for m in wanted.parse(frame)]
    expected = [m for frame in _frames() for m in _pymavlink(frame) if m.get_type() != "ATTITUDE"]
    assert [m.get_msgbuf() for m in got] == [m.get_msgbuf() for m in expected]
    assert [m.to_dict() for m in got] == [m.to_dict() for m in expected]
    assert [m.system_status for m in got if m.get_type() == "HEARTBEAT"] == [3, 4, 5]
    assert wanted.skipped == 1


def test_several_frames_in_one_datagram():
    frames = _frames()
    got = MessageFilter(("ATTITUDE", "STATUSTEXT")).parse(b"".join(frames))
    assert [m.get_type() for m in got] == ["ATTITUDE", "STATUSTEXT"]


def test_a_wanted_frame_with_a_bad_checksum_is_bad_data_and_an_unwanted_one_is_skipped():
    heartbeat, attitude = _frames()[:2]
    broken_hb = heartbeat[:-1] + bytes([heartbeat[-1] ^ 0xFF])
    broken_att = attitude[:-1] + bytes([attitude[-1] ^ 0xFF])
    wanted = MessageFilter(("HEARTBEAT",))
    assert [m.get_type() for m in wanted.parse(broken_hb)] == ["BAD_DATA"]
    assert wanted.parse(broken_att) == []


def test_a_frame_cut_short_never_swallows_the_next_datagram():
    heartbeat = _frames()[0]
    wanted = MessageFilter(("HEARTBEAT",))
    assert [m.get_type() for m in wanted.parse(heartbeat[:-3])] == ["BAD_DATA"]
    assert [m.get_type() for m in wanted.parse(heartbeat)] == ["HEARTBEAT"]


def test_garbage_before_a_frame_is_bad_data_then_the_frame():
    wanted = MessageFilter(("HEARTBEAT",))
    got = wanted.parse(b"\x01\x02\x03" + _frames()[0] + _frames()[1])
    assert [m.get_type() for m in got] == ["BAD_DATA", "HEARTBEAT"]


def test_add_all_decodes_every_frame_as_pymavlink_does():
    every = MessageFilter()
    every.add_all()
    data = b"".join(_frames())
    assert [m.get_msgbuf() for m in every.parse(data)] == [m.get_msgbuf() for m in _pymavlink(data)]


def test_a_kept_message_is_decoded_only_when_asked_and_only_its_newest_valid_frame():
    mav = dialect.MAVLink(None, srcSystem=1, srcComponent=1)
    frames = [mav.global_position_int_encode(i, 10 * i, 20 * i, 0, 0, 0, 0, 0, 0).pack(mav) for i in range(3)]
    broken = frames[2][:-1] + bytes([frames[2][-1] ^ 0xFF])
    kept = MessageFilter(("HEARTBEAT",))
    kept.keep_last("GLOBAL_POSITION_INT")
    assert kept.last("GLOBAL_POSITION_INT") is None
    assert [m for f in frames[:2] for m in kept.parse(f)] == []  # kept, not returned
    assert kept.last("GLOBAL_POSITION_INT").lat == 10
    assert kept.parse(broken) == []
    assert kept.last("GLOBAL_POSITION_INT").lat == 10  # a bad newest frame leaves the last valid message
    kept.add_all()
    kept.parse(frames[2])
    assert kept.last("GLOBAL_POSITION_INT").lat == 20


def test_an_unknown_name_is_one_sentence():
    with pytest.raises(ValueError, match=r"^pymavlink's development dialect has no message named NOT_A_MESSAGE\.$"):
        MessageFilter(("NOT_A_MESSAGE",))
    assert message_id("local_position_ned") == 32


def test_the_flight_client_decodes_only_what_it_reads(monkeypatch):
    decoded: list[tuple[int, str]] = []
    decode = dialect.MAVLink.decode

    def counting(self: Any, msgbuf: bytearray) -> Any:
        msg = decode(self, msgbuf)
        decoded.append((msg.get_srcSystem(), msg.get_type()))
        return msg

    monkeypatch.setattr(dialect.MAVLink, "decode", counting)
    with Sim() as sim:
        client = FlightClient(sim.ports(0).api, sim.clock)
        client.wait(lambda: client.healthy, 10.0, "health")
        client.spin(1.0)
        client.close()
        before_read = [kind for sysid, kind in decoded if sysid == 1]
        lat, lon = client.seen.lat_lon_deg or (0.0, 0.0)
    from_vehicle = {kind for sysid, kind in decoded if sysid == 1}
    assert {"HEARTBEAT", "LOCAL_POSITION_NED", "SYS_STATUS"} <= set(before_read) <= set(OBSERVED)
    assert from_vehicle == set(before_read) | {"GLOBAL_POSITION_INT"}  # decoded once, when read
    assert client.seen.pos_ned_m is not None and client.seen.home_seen
    assert abs(lat - DEFAULT_HOME[0]) < 1e-5 and abs(lon - DEFAULT_HOME[1]) < 1e-5
