"""Issue 25.9: a second joyfly on another port hears nothing from a vehicle that talks to a first client (PX4's API
link answers only the first client it heard); it must say the vehicle is busy, not that none runs."""

from __future__ import annotations

import socket
from collections.abc import Iterator

import pytest
from pymavlink.dialects.v20 import common as mavlink2
from support.joyfly_fakes import TimedSticks
from support.ports import free_udp_port

from joyfly.link.transport import UdpTransport
from joyfly.link.vehicle_link import VehicleLink
from joyfly.session.core import Phase, SessionSettings
from joyfly.session.flight_session import FlightSession
from joyfly.types import StickCommand
from sitl_emu.testing.sim import Sim


@pytest.fixture
def sim() -> Iterator[Sim]:
    with Sim() as s:
        yield s


def joyfly_on(sim: Sim, vehicle: tuple[str, int]) -> FlightSession:
    transport = UdpTransport(("127.0.0.1", 0), vehicle)
    return FlightSession(VehicleLink(transport, sim.clock), TimedSticks(sim.clock, [(0.0, StickCommand())]),
                         sim.clock, SessionSettings(connect_timeout_s=3.0))


def run(session: FlightSession, sim: Sim, until_s: float) -> None:
    end = sim.clock.now() + until_s
    while not session.finished and sim.clock.now() < end:
        session.run_once()


def test_a_second_client_is_told_the_vehicle_is_busy_with_another(sim: Sim) -> None:
    first = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)  # the first client (MAVSDK, another joyfly...)
    first.bind(("127.0.0.1", 0))
    mav = mavlink2.MAVLink(None, srcSystem=255, srcComponent=190)
    first.sendto(mav.heartbeat_encode(6, 8, 0, 0, 4).pack(mav), sim.ports(0).api)
    sim.run_for(0.5)
    second = joyfly_on(sim, sim.ports(0).api)
    try:
        run(second, sim, 10.0)
    finally:
        second.link.close()
        first.close()
    assert second.phase is Phase.FAILED and second.error is not None
    assert "the vehicle is probably busy with another client" in second.error, second.error
    assert "start `sitl-emu serve`" not in second.error


def test_with_nothing_on_the_vehicles_port_it_still_says_to_start_a_vehicle(sim: Sim) -> None:
    session = joyfly_on(sim, ("127.0.0.1", free_udp_port()))
    try:
        run(session, sim, 10.0)
    finally:
        session.link.close()
    assert session.error is not None and "start `sitl-emu serve` or PX4 SITL first" in session.error
    assert "busy" not in session.error


def test_a_vehicle_on_another_machine_cannot_be_told_busy() -> None:
    transport = UdpTransport(("127.0.0.1", 0), ("192.0.2.1", 14557))  # TEST-NET-1: never this machine's
    try:
        assert transport.vehicle_port_taken() is None
    finally:
        transport.close()
