"""The scripted client's kernel prefilter (sitl_emu/testing/kernel_filter.py), through real loopback sockets: it drops
exactly the single unsigned frames of messages not read, passes everything else, and a flight observes the same with
and without it (issue 28)."""

from __future__ import annotations

import socket
import sys
from collections.abc import Iterator
from typing import Any

import pytest
from pymavlink.dialects.v20 import development as dialect

from sitl_emu.testing import kernel_filter
from sitl_emu.testing.client import FlightClient, FlightResult, fly_square
from sitl_emu.testing.frames import message_id
from sitl_emu.testing.sim import Sim

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="a Linux socket filter")

SIGNING_KEY = bytes(range(32))
END = b"\xabend of test"  # garbage (passes every program here, 0xAB first): marks the end of what was sent


@pytest.fixture
def pair() -> Iterator[tuple[socket.socket, socket.socket]]:
    rx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    rx.bind(("127.0.0.1", 0))
    rx.settimeout(2.0)
    tx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    tx.connect(rx.getsockname())
    yield rx, tx
    rx.close()
    tx.close()


def _through(pair: tuple[socket.socket, socket.socket], datagrams: list[bytes]) -> list[bytes]:
    """The datagrams that reach the receiving socket, in order."""
    rx, tx = pair
    for data in [*datagrams, END]:
        tx.send(data)
    got = []
    while (data := rx.recv(65535)) != END:
        got.append(data)
    return got


def _mav(version: str = "2.0", signed: bool = False) -> Any:
    mav = dialect.MAVLink(None, srcSystem=1, srcComponent=1)
    if signed:
        mav.signing.secret_key = SIGNING_KEY
        mav.signing.sign_outgoing = True
    mav.WIRE_PROTOCOL_VERSION = version
    return mav


def _heartbeat(mav: Any) -> bytes:
    return bytes(mav.heartbeat_encode(2, 12, 0, 0, 3).pack(mav, force_mavlink1=mav.WIRE_PROTOCOL_VERSION == "1.0"))


def _attitude(mav: Any) -> bytes:
    msg = mav.attitude_encode(10, 0.1, 0.2, 0.3, 0, 0, 0)
    return bytes(msg.pack(mav, force_mavlink1=mav.WIRE_PROTOCOL_VERSION == "1.0"))


def _with_id(frame: bytes, msg_id: int) -> bytes:
    """A MAVLink 2 frame with another 24-bit message id in its header (the checksum no longer matches)."""
    return frame[:7] + msg_id.to_bytes(3, "little") + frame[10:]


def _flagged_signed(frame: bytes) -> bytes:
    """A MAVLink 2 frame whose incompat flags say signed, without the signature (pymavlink: bad data)."""
    return frame[:2] + bytes([frame[2] | 0x01]) + frame[3:]


def test_a_socket_filter_sees_the_datagram_after_the_udp_header(pair):
    """The module's assumption, on the running kernel: the datagram's first byte is at UDP_HEADER."""
    first_byte_is_0xab = [(kernel_filter.LDB_ABS, 0, 0, kernel_filter.UDP_HEADER), (kernel_filter.JEQ_K, 0, 1, 0xAB),
                          (kernel_filter.RET_K, 0, 0, kernel_filter.PASS), (kernel_filter.RET_K, 0, 0, 0)]
    assert kernel_filter.attach_program(pair[0], first_byte_is_0xab)
    assert _through(pair, [b"\xab\x01", b"\x01\xab", b"\xab"]) == [b"\xab\x01", b"\xab"]


def test_only_the_single_frames_of_other_messages_are_dropped(pair):
    v2, v1, signer = _mav(), _mav("1.0"), _mav(signed=True)
    hb, att = _heartbeat(v2), _attitude(v2)
    passed = [hb, _heartbeat(v1), _with_id(att, 0x010203),  # wanted: HEARTBEAT (0), 0x010203
              _attitude(signer), _flagged_signed(att),  # signed, or says so
              hb + att, att + att, att[:-1], att + b"\x00",  # several frames, cut short, too long
              b"", b"\xfd", b"\xfd\x09\x00", b"\x01\x02\x03\x04\x05\x06\x07\x08", b"\x00" + att]  # short, garbage
    dropped = [att, _attitude(v1), _with_id(att, 0x010000), _with_id(att, 0x000100)]  # 0x010000: not HEARTBEAT
    assert kernel_filter.attach(pair[0], {message_id("HEARTBEAT"), 0x010203})
    assert _through(pair, [*dropped, *passed, *dropped]) == passed


def test_a_new_set_replaces_the_old_and_none_lets_everything_through(pair):
    hb, att = _heartbeat(_mav()), _attitude(_mav())
    assert kernel_filter.attach(pair[0], {message_id("ATTITUDE")})
    assert _through(pair, [hb, att]) == [att]
    assert kernel_filter.attach(pair[0], set())
    assert _through(pair, [hb, att]) == []
    assert not kernel_filter.attach(pair[0], None)
    assert _through(pair, [hb, att]) == [hb, att]
    assert not kernel_filter.attach(pair[0], range(kernel_filter.MAX_IDS + 1))  # too many: Python filters
    assert _through(pair, [hb, att]) == [hb, att]
    kernel_filter.detach(pair[0])  # detaching twice is fine


class Recorder(FlightClient):
    """Keeps every message the client observes (its bytes, in order)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.observed: list[bytes] = []

    def _observe(self, msg: Any) -> None:
        self.observed.append(bytes(msg.get_msgbuf()))
        super()._observe(msg)


def _fly(kernel: bool) -> tuple[FlightResult, Recorder, tuple[float, float] | None]:
    with Sim() as sim:
        client = Recorder(sim.ports(0).api, sim.clock, kernel_filter=kernel)
        result = fly_square(client, side_m=2.0)
        client.close()
        return result, client, client.seen.lat_lon_deg


def test_a_flight_observes_the_same_with_and_without_the_kernel_filter():
    filtered, client_f, lat_lon_f = _fly(True)
    plain, client_p, lat_lon_p = _fly(False)
    assert filtered.ok, filtered.error
    assert filtered == plain
    assert client_f.observed == client_p.observed and len(client_f.observed) > 1000
    assert (client_f.seen.acks, client_f.seen.texts) == (client_p.seen.acks, client_p.seen.texts)
    assert lat_lon_f == lat_lon_p is not None
    assert client_f._parser.skipped == 0  # the kernel dropped every frame the parser would skip
    assert client_p._parser.skipped > 4 * len(client_p.observed)
