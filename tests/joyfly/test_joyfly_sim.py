"""joyfly's session against sitl_emu's vehicle (sitl_emu.testing.sim.Sim: real MAVLink over loopback UDP, in lockstep on
simulated time): several flights against one vehicle that is not restarted in between, and a vehicle restarted in
the middle of a flight."""

from __future__ import annotations

import math
from collections.abc import Iterator

import pytest
from support.joyfly_fakes import TimedSticks

from joyfly.link.transport import UdpTransport
from joyfly.link.vehicle_link import VehicleLink
from joyfly.session.flight_session import FlightSession, Phase, SessionSettings
from joyfly.types import Action, StickCommand
from sitl_emu.testing.sim import Sim

LAND = StickCommand(pressed=frozenset({Action.LAND}))


@pytest.fixture
def sim() -> Iterator[Sim]:
    with Sim() as s:
        yield s


def session_on(sim: Sim, steps: list[tuple[float, StickCommand]], port: int = 0, **settings: object) -> FlightSession:
    """A new `joyfly fly` against the Sim's vehicle on local UDP `port` (as PX4, the vehicle answers the first
    client it heard, so a second run binds the same port as the first), its sticks timed from now."""
    transport = UdpTransport(("127.0.0.1", port), sim.ports(0).api)
    return FlightSession(VehicleLink(transport, sim.clock), TimedSticks(sim.clock, steps), sim.clock,
                         SessionSettings(**settings))  # type: ignore[arg-type]


def run(session: FlightSession, sim: Sim, until_s: float) -> None:
    end = sim.clock.now() + until_s
    while not session.finished and sim.clock.now() < end:
        session.run_once()


@pytest.mark.slow
def test_the_fence_is_centred_on_the_home_of_the_second_flight_not_the_first(sim: Sim) -> None:
    first = session_on(sim, [(0.0, StickCommand()), (8.0, StickCommand(forward=0.6)), (10.0, StickCommand()),
                             (14.0, LAND), (14.5, StickCommand())], fence_m=10.0, exit_when_landed=True)
    run(first, sim, 60.0)
    first.link.close()
    landed = sim.vehicle(0).snapshot()
    assert first.phase is Phase.DONE and not landed.armed, first.error
    assert landed.pos_ned_m[0] > 4.0  # landed well away from the first flight's home, (0, 0, 0)

    # the joystick comes 3 s after the vehicle: by then joyfly has heard the vehicle's (old) HOME_POSITION
    second = session_on(sim, [(0.0, StickCommand(connected=False)), (3.0, StickCommand())],
                        port=first.link.transport.local_port, fence_m=2.0)
    run(second, sim, 3.0)
    assert second.link.state.home_ned_m == pytest.approx((0.0, 0.0, 0.0), abs=0.1)
    run(second, sim, 12.0)
    second.link.close()
    now = sim.vehicle(0).snapshot()
    assert second.phase is Phase.FLYING, "\n".join(n.text for n in second.notes)
    assert second.fence.home_ned_m[:2] == pytest.approx(landed.pos_ned_m[:2], abs=0.1)
    assert math.dist(now.pos_ned_m[:2], landed.pos_ned_m[:2]) < 0.3  # straight up, no slide to the fence's edge
    assert second.stats.min_fence_margin_m > 1.5
    home = second.link.state.home_ned_m  # what the vehicle reports as home now: set where it armed this time
    assert home is not None and home[:2] == pytest.approx(landed.pos_ned_m[:2], abs=0.3)


def test_a_vehicle_restarted_in_flight_is_reported_and_left_alone(sim: Sim) -> None:
    session = session_on(sim, [(0.0, StickCommand())])
    run(session, sim, 12.0)
    assert session.phase is Phase.FLYING
    sim.vehicle(0).reboot()
    run(session, sim, 8.0)
    session.link.close()
    notes = "\n".join(n.text for n in session.notes)
    assert "The vehicle restarted (its time since boot went back from 12." in notes
    assert "will not arm it again on its own" in notes and "Link back" not in notes
    assert session.phase is Phase.GROUNDED and not sim.vehicle(0).snapshot().armed
