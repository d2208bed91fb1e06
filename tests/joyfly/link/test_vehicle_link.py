"""joyfly's MAVLink client and transports: connection URLs, UDP retargeting, clear errors, and the conversation
with a (fake) PX4 over real loopback UDP: vehicle identification, GCS heartbeats, ACKs, retries, STATUSTEXT."""

from __future__ import annotations

import socket
import time

import pytest
from pymavlink.dialects.v20 import common as mavlink2
from support.joyfly_fakes import FakeVehicle, WallStepper
from support.joyfly_sim import SimClock, memory_pair

from joyfly.link.transport import TransportError, UdpTransport, open_transport, parse_udp_url
from joyfly.link.vehicle_link import VehicleLink, VehicleState
from joyfly.sticks.setpoints import Setpoint
from px4common.clock import WallClock


def test_mavros_style_url_gives_bind_and_remote() -> None:
    assert parse_udp_url("udp://:14540@127.0.0.1:14557") == (("0.0.0.0", 14540), ("127.0.0.1", 14557))
    assert parse_udp_url("udp://127.0.0.1:0@") == (("127.0.0.1", 0), None)
    assert parse_udp_url("udp://:14540@10.0.0.2") == (("0.0.0.0", 14540), ("10.0.0.2", 14555))
    assert parse_udp_url("udp://:14540@127.0.0.1:14580/?ids=255,240") == (("0.0.0.0", 14540), ("127.0.0.1", 14580))


@pytest.mark.parametrize("url", ["bogus://x", "udp://:notaport@", "zmq:1234"])
def test_bad_urls_end_in_one_sentence(url: str) -> None:
    with pytest.raises(TransportError) as err:
        open_transport(url)
    assert str(err.value).endswith(".") and "\n" not in str(err.value)


def test_port_in_use_says_what_to_do() -> None:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as busy:
        busy.bind(("127.0.0.1", 0))
        port = busy.getsockname()[1]
        with pytest.raises(TransportError, match=f"UDP port {port} is already in use"):
            open_transport(f"udp://127.0.0.1:{port}@127.0.0.1:14557")


def test_udp_sends_to_the_given_remote_then_answers_the_sender() -> None:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as first, \
            socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as vehicle:
        first.bind(("127.0.0.1", 0))
        vehicle.bind(("127.0.0.1", 0))
        first.settimeout(2.0)
        vehicle.settimeout(2.0)
        transport = open_transport(f"udp://127.0.0.1:0@127.0.0.1:{first.getsockname()[1]}")
        assert isinstance(transport, UdpTransport)
        try:
            transport.write(b"hello")
            assert first.recv(100) == b"hello"
            vehicle.sendto(b"hb", ("127.0.0.1", transport.local_port))
            assert transport.read(2.0) == b"hb"
            transport.write(b"reply")  # like mavconn: answer whoever spoke last (PX4 binds 14580, not 14557)
            assert vehicle.recv(100) == b"reply"
        finally:
            transport.close()


def test_udpin_waits_for_the_vehicle_before_sending() -> None:
    transport = open_transport("udpin:127.0.0.1:0")
    try:
        transport.write(b"nobody to send to")  # must not raise
        assert transport.read(0.0) == b""
    finally:
        transport.close()


def test_the_vehicle_state_names_px4_custom_mode() -> None:
    offboard = VehicleState(last_heartbeat_s=0.0, custom_mode=6 << 16)
    assert offboard.mode == "OFFBOARD" and offboard.offboard
    loiter = VehicleState(last_heartbeat_s=0.0, custom_mode=50593792)
    assert loiter.mode == "AUTO.LOITER" and not loiter.offboard
    assert VehicleState(custom_mode=6 << 16).mode == "-"  # no heartbeat yet


@pytest.mark.slow
def test_over_udp_link_finds_the_vehicle_and_tracks_its_state() -> None:
    theirs = UdpTransport(("127.0.0.1", 0), None)
    ours = UdpTransport(("127.0.0.1", 0), ("127.0.0.1", theirs.local_port))
    vehicle = FakeVehicle(theirs, pos=[1.0, 2.0, 0.0])
    link = VehicleLink(ours, WallClock())
    try:
        with WallStepper(vehicle):
            end = time.monotonic() + 3.0
            while time.monotonic() < end and (link.state.pos_ned_m is None or link.state.landed_state == 0):
                link.tick()
                link.poll(0.05)
        assert (link.state.sysid, link.state.compid) == (1, 1)
        assert link.state.pos_ned_m == pytest.approx((1.0, 2.0, 0.0))
        assert link.state.mode == "AUTO.LOITER" and not link.state.armed
        assert link.state.landed_state == 1
        beats = vehicle.received("HEARTBEAT")
        assert beats and beats[0][1] == (6, 8, 255, 190)
    finally:
        ours.close()
        theirs.close()


def _sim_pair(**vehicle_kw: object) -> tuple[SimClock, FakeVehicle, VehicleLink]:
    clock = SimClock(max_step_s=0.005)
    ours, theirs = memory_pair()
    vehicle = FakeVehicle(theirs, **vehicle_kw)  # type: ignore[arg-type]
    link = VehicleLink(ours, clock)
    clock.on_advance(vehicle.step)
    clock.on_advance(lambda now: (link.poll(0.0), link.tick()))
    clock.sleep(1.5)
    return clock, vehicle, link


def test_command_ack_and_refusal_reason_arrive() -> None:
    clock, _vehicle, link = _sim_pair(refuse_arm_reason="Arming denied: Resolve system health failures first")
    handle = link.arm()
    clock.sleep(0.2)
    assert handle.done and handle.describe() == "TEMPORARILY_REJECTED"
    texts = [t.text for t in link.statustexts]
    assert "Arming denied: Resolve system health failures first" in texts  # reassembled from two chunks, tab gone


def test_unanswered_commands_are_sent_three_times_then_time_out() -> None:
    clock, vehicle, link = _sim_pair()
    vehicle.speak = False
    handle = link.land()
    clock.sleep(2.0)
    vehicle.speak = True
    clock.sleep(0.01)
    assert handle.timed_out and handle.describe() == "no answer from the vehicle"
    sent = [m for _, m in vehicle.received("CMD21")]
    assert [m.confirmation for m in sent] == [0, 1, 2]


def test_setpoint_message_carries_position_velocity_and_yaw_in_local_ned() -> None:
    clock, vehicle, link = _sim_pair()
    link.send_setpoint(Setpoint((1.0, -2.0, -3.0), 0.5, (0.5, 0.0, -0.2)))
    link.send_setpoint(Setpoint((4.0, 5.0, -6.0), -0.25))
    clock.sleep(0.01)
    (_, a), (_, b) = vehicle.received("SETPOINT")[-2:]
    assert (a.coordinate_frame, a.type_mask, a.target_system, a.target_component) == (1, 2496, 1, 1)
    assert (a.x, a.y, a.z, a.vx, a.vz, a.yaw) == pytest.approx((1.0, -2.0, -3.0, 0.5, -0.2, 0.5))
    assert b.type_mask == 2552 and (b.x, b.y, b.z, b.yaw) == pytest.approx((4.0, 5.0, -6.0, -0.25))


def test_other_ground_stations_are_not_mistaken_for_the_vehicle() -> None:
    clock = SimClock()
    ours, theirs = memory_pair()
    link = VehicleLink(ours, clock)
    qgc = mavlink2.MAVLink(None, srcSystem=255, srcComponent=190)
    theirs.write(qgc.heartbeat_encode(6, 8, 0, 0, 4).pack(qgc))
    link.poll(0.0)
    assert link.state.sysid is None and not link.state.link_ok(clock.now())


def test_tcp_urls_go_through_pymavlink() -> None:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as server:
        server.bind(("127.0.0.1", 0))
        server.listen(1)
        server.settimeout(5.0)
        port = server.getsockname()[1]
        transport = open_transport(f"tcp://127.0.0.1:{port}")
        try:
            conn, _ = server.accept()
            with conn:
                conn.settimeout(5.0)
                conn.sendall(b"from vehicle")
                got = b""
                end = time.monotonic() + 3.0
                while len(got) < 12 and time.monotonic() < end:
                    got += transport.read(0.1)
                assert got == b"from vehicle"
                transport.write(b"from joyfly")
                assert conn.recv(100) == b"from joyfly"
        finally:
            transport.close()
