"""A Sim's link that nobody has talked to has no peer: it builds no message and sends nothing (issue 28), until the
first datagram makes its sender the peer, as PX4 latches it; a link given a remote streams from boot, as `serve`."""

from __future__ import annotations

import socket
from typing import Any

import pytest
from pymavlink.dialects.v20 import development as dialect

from sitl_emu.mavlink.telemetry import streams as telemetry
from sitl_emu.testing.sim import Sim

ATTITUDE_HZ_ONBOARD = 100


def _count_builds(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """The message ids every stream builder is called for (table entries replaced: the compiled build runs it too)."""
    calls: list[int] = []
    for msg_id, builder in list(telemetry.STREAMS.items()):
        def counted(ctx: Any, snap: Any, msg_id: int = msg_id, builder: Any = builder) -> Any:
            calls.append(msg_id)
            return builder(ctx, snap)

        monkeypatch.setitem(telemetry.STREAMS, msg_id, counted)
    return calls


class Peer:
    """A plain pymavlink peer on a loopback port: talks once, then keeps what it receives."""

    def __init__(self) -> None:
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 21)
        self.sock.bind(("127.0.0.1", 0))
        self.sock.setblocking(False)
        self.mav = dialect.MAVLink(None, srcSystem=255, srcComponent=190)
        self.parser = dialect.MAVLink(None)
        self.received: list[Any] = []

    def heartbeat(self, to: tuple[str, int]) -> None:
        self.sock.sendto(self.mav.heartbeat_encode(18, 8, 0, 0, 4).pack(self.mav), to)

    def drain(self) -> list[str]:
        while True:
            try:
                data, _ = self.sock.recvfrom(65535)
            except BlockingIOError:
                break
            self.received.extend(self.parser.parse_buffer(data) or [])
        return [m.get_type() for m in self.received]

    def close(self) -> None:
        self.sock.close()


def test_links_nobody_talked_to_build_and_send_nothing(monkeypatch):
    calls = _count_builds(monkeypatch)
    with Sim() as sim:
        sim.run_for(3.0)
        node = sim.nodes[0]
        sent = [(ep.stats.tx_messages, ep.link.stats.tx_datagrams) for ep in node.endpoints]
        described = node.describe()
    assert calls == []
    assert sent == [(0, 0), (0, 0)]
    assert described.count("sends nothing until a peer talks") == 2


def test_the_first_datagram_makes_its_sender_the_peer_and_the_streams_start_at_once(monkeypatch):
    calls = _count_builds(monkeypatch)
    peer = Peer()
    try:
        with Sim() as sim:
            sim.run_for(1.0)
            peer.heartbeat(sim.ports(0).api)
            sim.run_for(0.004)  # one tick: the datagram is read, then everything is due on the new peer's link
            first_tick = peer.drain()
            sim.run_for(1.0)
            kinds = peer.drain()
            gcs_sent = sim.nodes[0].gcs.stats.tx_messages
    finally:
        peer.close()
    assert {"HEARTBEAT", "ATTITUDE", "LOCAL_POSITION_NED", "SYS_STATUS"} <= set(first_tick)
    assert abs(kinds.count("ATTITUDE") - ATTITUDE_HZ_ONBOARD) <= 2
    assert kinds.count("HEARTBEAT") == 2  # at the latch and one second later
    assert gcs_sent == 0  # the other link still has nobody
    assert calls.count(30) == kinds.count("ATTITUDE")  # built only for the peer's link, from the latch on


def test_a_link_given_a_remote_streams_from_boot_as_serve_does():
    peer = Peer()
    try:
        with Sim(gcs_remote=peer.sock.getsockname()) as sim:
            sim.run_for(0.004)
            kinds = peer.drain()
            api_sent = sim.nodes[0].api.stats.tx_messages
    finally:
        peer.close()
    assert "HEARTBEAT" in kinds and "ATTITUDE" in kinds
    assert api_sent == 0
