"""UDP link ends behave as PX4 SITL's: heartbeat from boot to the initial remote, latch on the first peer for good."""

from __future__ import annotations

import socket

import pytest
from support.fakes import Client, FakeVehicle, Harness

from sitl_emu.mavlink.link import UdpLink
from sitl_emu.mavlink.link_errors import PortInUseError
from sitl_emu.px4 import MavCmd
from sitl_emu.runtime.node import LinkSettings, VehicleNode


@pytest.fixture
def h():
    harness = Harness(FakeVehicle())
    yield harness
    harness.close()


def test_heartbeat_goes_to_the_initial_remote_from_boot_without_hearing_anyone(h):
    h.io()
    api_hb, gcs_hb = h.api.of_type("HEARTBEAT"), h.gcs.of_type("HEARTBEAT")
    assert len(api_hb) == 1 and len(gcs_hb) == 1
    assert api_hb[0].get_srcSystem() == 1 and api_hb[0].get_srcComponent() == 1
    assert api_hb[0].get_header().mlen > 0 and api_hb[0].get_msgbuf()[0] == 0xFD  # MAVLink 2 framing
    h.run(3.0)
    assert len(h.api.of_type("HEARTBEAT")) == 4  # t = 0, 1, 2, 3 s: 1 Hz on simulated time


def test_first_peer_is_latched_and_later_senders_are_parsed_but_not_answered(h):
    first, second = Client(), Client()
    try:
        first.target = second.target = h.api.target
        first.heartbeat()
        h.io()
        # parsed (a command from a stranger) but the reply goes to the first peer
        second.command_long(MavCmd.REQUEST_MESSAGE, 148)
        h.run(1.2)
        first.drain()
        second.drain()
        assert first.of_type("HEARTBEAT"), "the first peer receives the link's traffic"
        assert not second.received, "a later sender is never answered"
        assert [a.command for a in first.of_type("COMMAND_ACK")] == [MavCmd.REQUEST_MESSAGE]
        assert h.node.api.link.stats.rx_ignored_foreign == 1
        n_before = len(h.api.received)
        h.run(1.0)
        assert len(h.api.received) == n_before, "the initial remote no longer gets anything once a peer is latched"
    finally:
        first.close()
        second.close()


def test_each_link_latches_on_its_own(h):
    peer = Client()
    try:
        peer.target = h.gcs.target
        peer.heartbeat()
        h.io()
        gcs_before, api_before = len(h.gcs.of_type("HEARTBEAT")), len(h.api.of_type("HEARTBEAT"))
        h.run(2.0)
        peer.drain()
        assert len(peer.of_type("HEARTBEAT")) == 3  # t = 0 (same read as the latch), 1, 2 s
        assert len(h.gcs.of_type("HEARTBEAT")) == gcs_before == 0, "GCS link answers its peer only"
        assert len(h.api.of_type("HEARTBEAT")) == api_before + 2, "API link still sends to its initial remote"
    finally:
        peer.close()


def test_a_port_in_use_is_one_sentence_naming_the_port():
    holder = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    holder.bind(("127.0.0.1", 0))
    port = holder.getsockname()[1]
    try:
        with pytest.raises(PortInUseError) as err:
            UdpLink("127.0.0.1", port, ("127.0.0.1", 14540), "API")
        text = str(err.value)
        assert str(port) in text and text.endswith(".") and text.count(". ") == 0
    finally:
        holder.close()


def test_node_releases_the_first_port_when_the_second_is_taken():
    holder = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    holder.bind(("127.0.0.1", 0))
    taken = holder.getsockname()[1]
    free = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    free.bind(("127.0.0.1", 0))
    api_port = free.getsockname()[1]
    free.close()
    try:
        with pytest.raises(PortInUseError):
            VehicleNode(FakeVehicle(), LinkSettings("127.0.0.1", api_port, ("127.0.0.1", 9), taken), handler_classes=())
        UdpLink("127.0.0.1", api_port, ("127.0.0.1", 9)).close()  # still bindable: nothing leaked
    finally:
        holder.close()


def test_instance_offsets_ports_like_px4():
    s = LinkSettings().for_instance(2)
    assert (s.api_port, s.api_remote[1], s.gcs_port, s.gcs_remote[1]) == (14559, 14542, 18572, 14550)


def test_messages_not_only_for_us_are_forwarded_to_the_other_link_unchanged(h):
    """Both SITL links run with -f: heartbeats and broadcasts pass between the GCS and API peers as PX4 does."""
    qgc, mavros = h.gcs, h.api
    mavros.heartbeat(18)  # MAVROS identity differs: sysid 1, compid 191 on a real setup; here 255/190 on both
    qgc.heartbeat(6)
    qgc.command_long(MavCmd.REQUEST_MESSAGE, 148)  # for us (1/1): answered, never forwarded
    h.io()
    forwarded = [m for m in mavros.received if m.get_srcSystem() == 255]
    assert [m.get_type() for m in forwarded] == ["HEARTBEAT"]
    assert forwarded[0].type == 6 and bytes(forwarded[0].get_msgbuf())[0] == 0xFD
    assert not [m for m in mavros.received if m.get_type() == "COMMAND_LONG"]
    arm = MavCmd.COMPONENT_ARM_DISARM
    mavros.send(mavros.mav.command_ack_encode(arm, 0, 0, 0, 255, 190))  # to a component heard on the GCS link
    mavros.send(mavros.mav.command_ack_encode(arm, 0, 0, 0, 42, 42))  # to nobody we know
    h.io()
    acks = qgc.of_type("COMMAND_ACK", source=(255, 190))  # forwarded ones, not the vehicle's own
    assert [(a.target_system, a.target_component) for a in acks] == [(255, 190)]
    assert (h.node.gcs.stats.tx_forwarded, h.node.api.stats.tx_forwarded) == (2, 1)  # +MAVROS heartbeat


def test_a_link_without_remote_sends_nothing_until_a_peer_talks_then_answers_it():
    link = UdpLink("127.0.0.1", 0, None, "GCS")
    peer = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    peer.bind(("127.0.0.1", 0))
    peer.settimeout(2.0)
    try:
        assert not link.has_peer
        link.send(b"dropped")
        assert link.stats.tx_datagrams == link.stats.tx_errors == 0
        peer.sendto(b"hello", link.local_address)
        while not link.receive():
            pass
        assert link.has_peer and link.remote == peer.getsockname()
        link.send(b"answer")
        assert peer.recvfrom(100)[0] == b"answer"
    finally:
        link.close()
        peer.close()
