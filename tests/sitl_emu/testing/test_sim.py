"""The in-process API (sitl_emu.testing.sim): vehicles on loopback UDP stepped in lockstep with a scripted client.

A test suite drives real MAVLink over real sockets and still runs whole flights in a fraction of their simulated
duration, with the same result every run; joyfly's session flies on the same simulated clock.
"""

from __future__ import annotations

import math
import socket
import time

import pytest
from pymavlink.dialects.v20 import development as dialect

from sitl_emu.px4 import MavCmd, NavState
from sitl_emu.testing.client import FlightClient, fly_square
from sitl_emu.testing.sim import Sim


def _fly(seed: int = 0, noise_m: float = 0.0, **params: float) -> tuple[object, list[tuple[float, ...]], float, Sim]:
    """Fly the reference square; returns the result, the vehicle's trace (every 0.5 s) and the wall time."""
    sim = Sim(seed=seed, params=params, estimate_noise={"pos_white_m": noise_m})
    client = FlightClient(sim.ports(0).api, sim.clock)
    trace: list[tuple[float, ...]] = []
    original = sim.advance_to

    def advance_and_record(target_us: int) -> None:
        original(target_us)
        v = sim.vehicle(0)
        if v.time_us % 500_000 == 0 and (not trace or trace[-1][0] != v.time_us):
            s = v.snapshot()
            trace.append((v.time_us, *s.pos_ned_m, *s.q_wxyz))

    sim.advance_to = advance_and_record  # type: ignore[method-assign]
    start = time.perf_counter()
    result = fly_square(client)
    wall_s = time.perf_counter() - start
    client.close()
    return result, trace, wall_s, sim


@pytest.mark.slow
def test_scripted_flight_over_loopback_udp_takes_a_small_fraction_of_its_simulated_time():
    result, _, wall_s, sim = _fly()
    sim.close()
    assert result.ok, result.error
    modes = list(result.modes)
    flown = [m for m in ("AUTO.TAKEOFF", "AUTO.LOITER", "OFFBOARD", "AUTO.LAND") if m in modes]
    assert flown == ["AUTO.TAKEOFF", "AUTO.LOITER", "OFFBOARD", "AUTO.LAND"]
    assert modes.index("AUTO.TAKEOFF") < modes.index("OFFBOARD") < modes.index("AUTO.LAND")
    assert result.landing_ned_m is not None and math.hypot(*result.landing_ned_m[:2]) < 1.0
    assert result.sim_duration_s > 20.0
    assert wall_s / result.sim_duration_s < 0.5  # generous: typically ~0.05


@pytest.mark.slow
def test_same_script_seed_and_params_give_the_same_trajectory_every_run():
    first, trace_a, _, sim_a = _fly(seed=7, noise_m=0.02)
    second, trace_b, _, sim_b = _fly(seed=7, noise_m=0.02)
    other, trace_c, _, sim_c = _fly(seed=8, noise_m=0.02)
    events_a = [(e.time_us, e.text) for e in sim_a.vehicle(0).events_after(0)]
    events_b = [(e.time_us, e.text) for e in sim_b.vehicle(0).events_after(0)]
    for sim in (sim_a, sim_b, sim_c):
        sim.close()
    assert first.ok and second.ok and other.ok
    assert len(trace_a) > 40
    assert trace_a == trace_b  # bit for bit, every 0.5 s of the flight, seeded position noise included
    assert events_a == events_b
    assert first.landing_ned_m == second.landing_ned_m
    assert trace_c != trace_a  # the seed does reach the noise


@pytest.mark.slow
def test_params_change_the_flight():
    result, trace, _, sim = _fly(MIS_TAKEOFF_ALT=4.0)
    sim.close()
    assert result.ok, result.error
    assert min(z for _, _, _, z, *_ in trace) < -3.5  # the default takeoff altitude is 2.5 m


@pytest.mark.slow
def test_joyfly_session_flies_a_sim_vehicle_on_the_lockstep_clock():
    from joyfly.config import FlyOptions
    from joyfly.demo import script_source
    from joyfly.link.transport import UdpTransport
    from joyfly.link.vehicle_link import VehicleLink
    from joyfly.session.flight_session import FlightSession, Phase

    with Sim() as sim:
        transport = UdpTransport(("127.0.0.1", 0), sim.ports(0).api)
        session = FlightSession(VehicleLink(transport, sim.clock), script_source(None, sim.clock), sim.clock,
                                FlyOptions().session_settings(exit_when_landed=True))
        session.run()
        transport.close()
        snap = sim.vehicle(0).snapshot()
    assert session.phase is Phase.DONE, session.error
    assert session.stats.control_time_s > 20.0 and session.stats.distance_m > 10.0
    assert not snap.armed and snap.pos_ned_m[2] > -0.1
    assert 30.0 < sim.clock.now() < 120.0


def test_two_vehicles_get_their_own_ports_sysids_and_homes():
    with Sim(count=2) as sim:
        ports = [sim.ports(0), sim.ports(1)]
        clients = [FlightClient(p.api, sim.clock, target_sysid=p.sysid) for p in ports]
        for c in clients:
            c.wait(lambda c=c: c.seen.heartbeat is not None and c.seen.home_seen, 5.0, "heartbeat")
        sysids = [c.seen.heartbeat.get_srcSystem() for c in clients]
        homes = [v.snapshot() for v in sim.vehicles]
        for c in clients:
            c.close()
    assert [p.sysid for p in ports] == sysids == [1, 2]
    assert len({p.api for p in ports} | {p.gcs for p in ports}) == 4
    east_m = (homes[1].lon_deg - homes[0].lon_deg) * math.radians(1) * 6371000 * math.cos(math.radians(47.4))
    assert 2.5 < east_m < 3.5 and abs(homes[1].lat_deg - homes[0].lat_deg) < 1e-7


def test_background_real_time_then_back_to_lockstep():
    with Sim() as sim:
        sim.run_for(0.5)
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        sock.bind(("127.0.0.1", 0))
        sock.settimeout(2.0)
        mav = dialect.MAVLink(None, srcSystem=255, srcComponent=190)
        sim.start(speed=20.0)
        sock.sendto(mav.heartbeat_encode(6, 8, 0, 0, 4).pack(mav), sim.ports(0).gcs)
        parser = dialect.MAVLink(None)
        got = []
        while not any(m.get_type() == "HEARTBEAT" for m in got):
            data, _ = sock.recvfrom(65535)  # a client on its own wall-clock timers is answered
            got.extend(parser.parse_buffer(data) or [])
        time.sleep(0.1)
        sim.stop()
        reached = sim.time_us
        assert reached > 600_000
        sim.run_for(1.0)
        assert sim.time_us == reached + 1_000_000
        assert sim.vehicle(0).snapshot().nav_state == NavState.AUTO_LOITER
        sock.close()


def test_a_plain_pymavlink_connection_talks_to_a_lockstep_vehicle():
    from pymavlink import mavutil

    with Sim() as sim:
        host, port = sim.ports(0).api
        conn = mavutil.mavlink_connection(f"udpout:{host}:{port}", source_system=255, source_component=190)
        try:
            conn.mav.heartbeat_send(6, 8, 0, 0, 4)  # talk first: the API link latches us as its partner
            msgs = []
            for _ in range(25):  # 2.5 s, reading as we go (the socket buffer holds well under a second of streams)
                sim.run_for(0.1)
                while (msg := conn.recv_match(blocking=False)) is not None:
                    msgs.append(msg)
            conn.mav.command_long_send(1, 1, MavCmd.COMPONENT_ARM_DISARM, 0, 1, 0, 0, 0, 0, 0, 0)  # arm
            sim.run_for(0.1)
            while (msg := conn.recv_match(blocking=False)) is not None:
                msgs.append(msg)
        finally:
            conn.close()
    kinds = {m.get_type() for m in msgs}
    assert {"HEARTBEAT", "ATTITUDE", "LOCAL_POSITION_NED", "COMMAND_ACK"} <= kinds
    ack = next(m for m in msgs if m.get_type() == "COMMAND_ACK")
    assert (ack.command, ack.result) == (MavCmd.COMPONENT_ARM_DISARM, 0)
    assert sim.vehicle(0).snapshot().armed
