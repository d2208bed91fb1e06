"""`--control position` / `altitude` against sitl_emu's vehicle (sitl_emu.testing.sim.Sim: MAVLink over loopback UDP,
in lockstep on simulated time): PX4's manual flight as the emulator flies it, with joyfly's sticks and fence."""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, field

import pytest
from support.joyfly_fakes import TimedSticks

from joyfly.link.transport import UdpTransport
from joyfly.link.vehicle_link import VehicleLink
from joyfly.session.core import Phase, SessionSettings
from joyfly.session.factory import make_session
from joyfly.session.loop import SessionLoop
from joyfly.sticks.setpoints import Limits
from joyfly.types import StickCommand
from sitl_emu.testing.sim import Sim

CENTRE = StickCommand(up=0.0)


def stick(**axes: float) -> StickCommand:
    return StickCommand(up=axes.pop("up", 0.0), **axes)


@dataclass
class Flight:
    sim: Sim
    session: SessionLoop
    track: list[tuple[float, tuple[float, float, float]]] = field(default_factory=list)

    def run(self, until_s: float) -> None:
        while not self.session.finished and self.sim.clock.now() < until_s:
            self.session.run_once()
            self.track.append((self.sim.clock.now(), self.sim.vehicle(0).snapshot().pos_ned_m))

    def pos(self) -> tuple[float, float, float]:
        return self.sim.vehicle(0).snapshot().pos_ned_m

    def since(self, t_s: float) -> list[tuple[float, float, float]]:
        return [p for t, p in self.track if t >= t_s]

    def notes(self) -> str:
        return "\n".join(n.text for n in self.session.notes)


@pytest.fixture
def sim() -> Iterator[Sim]:
    with Sim() as s:
        yield s


def fly(sim: Sim, steps: list[tuple[float, StickCommand]], control: str = "position", **settings: object) -> Flight:
    transport = UdpTransport(("127.0.0.1", 0), sim.ports(0).api)
    session = make_session(VehicleLink(transport, sim.clock), TimedSticks(sim.clock, steps), sim.clock,
                           SessionSettings(rate_hz=25.0, limits=Limits(control=control), **settings))  # type: ignore[arg-type]
    return Flight(sim, session)


@pytest.mark.slow
def test_position_mode_takes_off_holds_flies_north_stops_at_the_fence_and_lands(sim: Sim) -> None:
    f = fly(sim, [(0.0, CENTRE), (5.0, stick(up=1.0)), (9.0, CENTRE), (14.0, stick(forward=0.5)),
                  (16.0, CENTRE), (20.0, stick(right=1.0))], fence_m=5.0)
    f.run(5.0)
    assert f.session.phase is Phase.FLYING and sim.vehicle(0).snapshot().armed, f.notes()
    assert "Armed by external command" in f.notes() and f.pos()[2] == pytest.approx(0.0, abs=0.05)
    f.run(11.0)
    assert -f.pos()[2] > 2.0 and "Takeoff detected" in f.notes()
    held = f.pos()
    f.run(14.0)
    assert max(abs(a - b) for a, b in zip(f.pos(), held, strict=True)) < 0.5  # centred sticks hold
    f.run(19.0)
    x, y, _ = f.pos()
    assert x > held[0] + 1.0 and abs(y - held[1]) < 0.3  # forward (the nose points north) flies north
    f.run(35.0)
    assert max(abs(p[1]) for p in f.since(20.0)) < 5.0 and f.pos()[1] > 4.0  # the held stick stops at the fence
    f.session.request_exit()
    f.run(80.0)
    assert f.session.phase is Phase.DONE and not sim.vehicle(0).snapshot().armed
    assert "Landed and disarmed" in f.notes() and "Failsafe" not in f.notes()


def test_altitude_mode_tilts_to_the_fence_and_stops_a_drift_inside(sim: Sim) -> None:
    f = fly(sim, [(0.0, CENTRE), (5.0, stick(up=1.0)), (9.0, CENTRE), (12.0, stick(forward=1.0, right=1.0)),
                  (27.0, CENTRE)], control="altitude", fence_m=6.0)
    f.run(12.0)
    assert f.sim.vehicle(0).snapshot().armed and -f.pos()[2] > 2.0, f.notes()
    assert "ALTCTL" in f.session.link.state.mode
    f.run(40.0)
    worst = max(max(abs(p[0]), abs(p[1])) for p in f.since(12.0))
    assert 4.0 < worst < 6.0


def test_the_throttle_stops_below_max_alt(sim: Sim) -> None:
    f = fly(sim, [(0.0, CENTRE), (5.0, stick(up=1.0))], max_alt_m=6.0)
    f.run(25.0)
    assert 4.5 < max(-p[2] for p in f.since(5.0)) < 6.0


def test_a_lost_joystick_holds_then_lands_without_px4s_stick_loss_failsafe(sim: Sim) -> None:
    f = fly(sim, [(0.0, CENTRE), (5.0, stick(up=1.0)), (9.0, CENTRE), (12.0, StickCommand(connected=False))],
            joy_timeout_s=3.0)
    f.run(14.0)
    assert f.session.link.state.mode == "AUTO.LOITER" and "Joystick lost: Hold" in f.notes()
    held = f.pos()
    f.run(14.9)
    assert math.dist(f.pos(), held) < 0.3
    f.run(60.0)
    assert f.session.phase is Phase.DONE and not sim.vehicle(0).snapshot().armed
    assert "Landing at current position" in f.notes() and "Failsafe" not in f.notes()


def test_ctrl_c_armed_on_the_ground_disarms_at_once_instead_of_landing(sim: Sim) -> None:
    """Issue 25.6: armed in Position mode, the throttle not yet pushed: Ctrl-C disarms as a pilot would; a LAND there
    only waited for PX4's auto-disarm."""
    f = fly(sim, [(0.0, CENTRE)])
    f.run(5.0)
    assert f.session.phase is Phase.FLYING and sim.vehicle(0).snapshot().armed, f.notes()
    asked_s = sim.clock.now()
    f.session.request_exit()
    while sim.vehicle(0).snapshot().armed and sim.clock.now() < asked_s + 15.0:
        f.session.run_once()
    assert sim.clock.now() - asked_s < 1.0, f.notes()  # disarmed within a second (LAND took several)
    f.run(asked_s + 3.0)
    assert f.session.phase is Phase.DONE and "Exiting: disarming on the ground" in f.notes()
    assert "Disarmed on the ground." in f.notes() and "Landing at current position" not in f.notes()
