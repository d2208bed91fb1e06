"""DO_ORBIT and FOLLOW_TARGET over loopback UDP (lockstep Sim, pymavlink): PX4's ACKs and texts, an orbit around a
point (radius, speed, direction, ORBIT_EXECUTION_STATUS, custom_mode), leaving it; following a moving target; the
target's stream lost; bad input. Sources: FlightTaskOrbit.cpp, Commander.cpp (DO_ORBIT), FlightTaskAutoFollowTarget.cpp,
TargetEstimator.cpp, mavlink_receiver.cpp handle_message_follow_target."""

from __future__ import annotations

import itertools
import math
import struct
from typing import Any

import pytest

from sitl_emu.geo import ned_to_global
from sitl_emu.px4 import MavCmd, MavResult, NavState, custom_mode
from sitl_emu.testing.client import FlightClient
from sitl_emu.testing.sim import Sim

NAN = math.nan
CENTRE_NED = (20.0, 0.0)


class Client(FlightClient):
    """FlightClient that also keeps ORBIT_EXECUTION_STATUS and the heartbeats' custom_mode."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.watch("ORBIT_EXECUTION_STATUS")
        self.orbit: list[Any] = []
        self.custom_modes: list[int] = []
        self._gcs_heartbeat_s = -math.inf

    def pump(self) -> None:
        """Also a GCS heartbeat: the vehicle sends STATUSTEXT only to a link with a ground station."""
        now = self.clock.now()
        if now >= self._gcs_heartbeat_s:
            self.send(self.mav.heartbeat_encode(6, 8, 0, 0, 4))
            self._gcs_heartbeat_s = now + 1.0
        super().pump()

    def _observe(self, msg: Any) -> None:
        super()._observe(msg)
        if msg.get_type() == "ORBIT_EXECUTION_STATUS":
            self.orbit.append(msg)
        elif msg.get_type() == "HEARTBEAT" and msg.get_srcSystem() == 1:
            self.custom_modes.append(msg.custom_mode)


@pytest.fixture
def flying():
    """A vehicle hovering at 2.5 m after a takeoff, and a GCS-link client."""
    sim = Sim()
    c = Client(sim.ports(0).gcs, sim.clock)
    c.wait(lambda: c.healthy, 10.0, "ready")
    assert c.command(MavCmd.COMPONENT_ARM_DISARM, 1) == MavResult.ACCEPTED
    assert c.command(MavCmd.NAV_TAKEOFF) == MavResult.ACCEPTED
    c.wait(lambda: sim.vehicle(0).snapshot().pos_ned_m[2] < -2.4, 15.0, "2.5 m up")
    c.spin(1.0)
    yield sim, c
    c.close()
    sim.close()


def _centre(sim: Sim) -> tuple[float, float, float]:
    return ned_to_global(sim.vehicle(0).ref, (*CENTRE_NED, 0.0))


def _track(sim: Sim, c: Client, seconds: float) -> list[tuple[float, float, float, float]]:
    """(radius from the centre, horizontal speed, angle around the centre, height) every 0.5 s."""
    out = []
    for _ in range(int(seconds * 2)):
        c.spin(0.5)
        s = sim.vehicle(0).snapshot()
        dx, dy = s.pos_ned_m[0] - CENTRE_NED[0], s.pos_ned_m[1] - CENTRE_NED[1]
        out.append((math.hypot(dx, dy), math.hypot(*s.vel_ned_m_s[:2]), math.atan2(dy, dx), -s.pos_ned_m[2]))
    return out


@pytest.mark.slow
def test_orbit_around_a_point_then_the_other_way_then_hold(flying):
    sim, c = flying
    lat, lon, _ = _centre(sim)
    assert c.command(MavCmd.DO_ORBIT, 10.0, 2.0, 0, NAN, lat, lon, NAN) == MavResult.ACCEPTED
    c.spin(14.0)  # approach the circle and settle
    assert c.custom_modes[-1] == custom_mode(NavState.ORBIT) == 16973824  # POSCTL.ORBIT
    n = len(c.orbit)
    track = _track(sim, c, 10.0)
    assert 16 <= len(c.orbit) - n <= 24  # 2 Hz on the GCS link
    assert max(abs(r - 10.0) for r, *_ in track) < 1.0
    speeds = [v for _, v, *_ in track]
    assert 1.5 < sum(speeds) / len(speeds) <= 2.1  # the commanded 2 m/s (SIH's drag costs a little)
    turns = [math.remainder(b[2] - a[2], math.tau) for a, b in itertools.pairwise(track)]
    assert all(t > 0 for t in turns)  # positive radius: clockwise seen from above (north -> east)
    assert all(abs(h - 2.5) < 0.5 for *_, h in track)  # the altitude is kept (NaN param7: current)
    o = c.orbit[-1]
    assert (o.radius, o.frame) == (10.0, 0)
    lat32, lon32 = (struct.unpack("<f", struct.pack("<f", v))[0] for v in (lat, lon))  # COMMAND_LONG: float32
    assert abs(o.x - lat32 * 1e7) <= 1 and abs(o.y - lon32 * 1e7) <= 1
    assert abs(o.z - (sim.vehicle(0).ref.alt_amsl_m + 2.5)) < 0.5
    # a new DO_ORBIT while orbiting: NaN keeps the centre, a negative radius turns the other way
    assert c.command(MavCmd.DO_ORBIT, -10.0, 2.0) == MavResult.ACCEPTED
    c.spin(4.0)
    track = _track(sim, c, 5.0)
    turns = [math.remainder(b[2] - a[2], math.tau) for a, b in itertools.pairwise(track)]
    assert all(t < 0 for t in turns) and c.orbit[-1].radius == -10.0
    # leaving: any mode change; the orbit status stops
    assert c.set_mode(NavState.AUTO_LOITER) == MavResult.ACCEPTED
    n = len(c.orbit)
    c.spin(6.0)
    assert len(c.orbit) - n <= 1
    assert math.hypot(*sim.vehicle(0).snapshot().vel_ned_m_s[:2]) < 0.3  # Hold: stopped
    assert c.custom_modes[-1] == custom_mode(NavState.AUTO_LOITER)


def test_orbit_when_disarmed_is_accepted_and_then_prevents_arming():
    """Commander.cpp: DO_ORBIT changes the user's mode (allowed while disarmed); Orbit prevents arming."""
    with Sim() as sim:
        c = Client(sim.ports(0).gcs, sim.clock)
        c.wait(lambda: c.healthy, 10.0, "ready")
        assert c.command(MavCmd.DO_ORBIT, 10.0, 2.0) == MavResult.ACCEPTED
        c.spin(1.0)
        assert c.custom_modes[-1] == custom_mode(NavState.ORBIT)
        assert c.command(MavCmd.COMPONENT_ARM_DISARM, 1) == MavResult.TEMPORARILY_REJECTED
        assert not c.orbit and not c.armed
        c.close()


@pytest.mark.slow
def test_bad_orbit_parameters_get_px4s_answers_and_nothing_flies_off(flying):
    sim, c = flying
    v = sim.vehicle(0)
    for radius, velocity, radius_flown in [(NAN, NAN, 1.0), (math.inf, -math.inf, 1.0), (20000.0, 2.0, None),
                                           (0.0, 2.0, None)]:
        start, n_text, n_orbit = v.snapshot().pos_ned_m, len(c.seen.texts), len(c.orbit)
        assert c.command(MavCmd.DO_ORBIT, radius, velocity) == MavResult.ACCEPTED  # the task judges, not commander
        c.spin(4.0)
        assert ("Orbit radius limit exceeded\t" in c.seen.texts[n_text:]) is (radius_flown is None)
        assert c.custom_modes[-1] == custom_mode(NavState.ORBIT)
        s = v.snapshot()
        assert all(math.isfinite(x) for x in s.pos_ned_m) and math.dist(s.pos_ned_m, start) < 2.0
        if radius_flown is None:  # the failsafe setpoint: it stays, and the orbit status stops
            assert len(c.orbit) - n_orbit <= 1
        else:  # NaN / inf keep the task's start values: 1 m around itself
            assert c.orbit[-1].radius == radius_flown


# ---- follow target -------------------------------------------------------------------------------------------------
def _send_target(c: Client, sim: Sim, ned: tuple[float, float], vel: tuple[float, float], alt: float | None = None
                 ) -> None:
    ref = sim.vehicle(0).ref
    lat, lon, amsl = ned_to_global(ref, (*ned, 0.0))
    c.send(c.mav.follow_target_encode(0, 0, round(lat * 1e7), round(lon * 1e7), amsl if alt is None else alt,
                                      [vel[0], vel[1], 0.0], [0, 0, 0], [1, 0, 0, 0], [NAN] * 3, [NAN] * 3, 0))


def _walk(sim: Sim, c: Client, start: tuple[float, float], vel: tuple[float, float], seconds: float,
          stream: bool = True) -> list[tuple[float, float]]:
    """The target walks from `start` (FOLLOW_TARGET at 5 Hz while `stream`); (distance, height) every 0.2 s."""
    out = []
    for i in range(int(seconds * 5)):
        t = i * 0.2
        pos = (start[0] + vel[0] * t, start[1] + vel[1] * t)
        if stream:
            _send_target(c, sim, pos, vel)
        c.spin(0.2)
        s = sim.vehicle(0).snapshot()
        out.append((math.hypot(s.pos_ned_m[0] - pos[0], s.pos_ned_m[1] - pos[1]), -s.pos_ned_m[2]))
    return out


@pytest.mark.slow
def test_follow_a_moving_target_then_lose_its_stream(flying):
    sim, c = flying
    v = sim.vehicle(0)
    v.params.set("FLW_TGT_DST", 6.0)
    assert c.set_mode(NavState.AUTO_FOLLOW_TARGET) == MavResult.ACCEPTED
    track = _walk(sim, c, (6.0, 0.0), (0.0, 2.0), 16.0)
    settled = track[50:]  # after 10 s
    assert all(abs(d - 6.0) < 1.0 for d, _ in settled)  # FLW_TGT_DST
    assert all(abs(h - 8.0) < 0.5 for _, h in settled)  # FLW_TGT_HT above home
    assert v.snapshot().pos_ned_m[1] < 2.0 * 15.8 - 4.0  # behind the target (FLW_TGT_FA 180)
    assert c.custom_modes[-1] == custom_mode(NavState.AUTO_FOLLOW_TARGET) == 134479872
    c.spin(10.0)  # no more FOLLOW_TARGET: after 3 s the estimate stops moving, the vehicle settles
    s = v.snapshot()
    assert math.hypot(*s.vel_ned_m_s[:2]) < 0.3  # station kept, not drifting on
    # it did not chase a target it no longer hears: the estimate coasts 3 s (6 m) before it stops, 6 m behind it
    assert s.pos_ned_m[1] < 2.0 * 15.8 + 3.0
    assert c.custom_modes[-1] == custom_mode(NavState.AUTO_FOLLOW_TARGET) and s.armed  # PX4 stays in the mode


@pytest.mark.slow
def test_follow_target_garbage_flies_nowhere(flying):
    sim, c = flying
    assert c.set_mode(NavState.AUTO_FOLLOW_TARGET) == MavResult.ACCEPTED
    start = sim.vehicle(0).snapshot().pos_ned_m
    for _ in range(20):
        _send_target(c, sim, (50.0, 50.0), (NAN, NAN), alt=NAN)  # a NaN altitude: no valid estimate
        c.send(c.mav.follow_target_encode(0, 0, 2**31 - 1, -(2**31), 500.0, [1e30, -1e30, 0], [0, 0, 0],
                                          [1, 0, 0, 0], [NAN] * 3, [NAN] * 3, 0))  # off the globe: dropped
        c.spin(0.2)
    s = sim.vehicle(0).snapshot()
    assert math.dist(s.pos_ned_m[:2], start[:2]) < 1.0
    assert all(math.isfinite(x) for x in s.pos_ned_m) and s.armed
