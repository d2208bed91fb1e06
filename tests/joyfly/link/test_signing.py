"""`joyfly fly --signing-key FILE [--setup-signing]` against sitl_emu's signing vehicle (Sim: real MAVLink over loopback
UDP in lockstep): with the key joyfly flies, without it the vehicle ignores it; --setup-signing gives a vehicle without
a key joyfly's (SETUP_SIGNING); a key file it cannot use is one sentence (the reader: px4common/signing_key.py)."""

from __future__ import annotations

import hashlib
from collections.abc import Iterator

import pytest
from click.testing import CliRunner
from support.joyfly_fakes import TimedSticks

from joyfly.cli import main
from joyfly.link.transport import UdpTransport
from joyfly.link.vehicle_link import VehicleLink
from joyfly.session.flight_session import FlightSession, Phase, SessionSettings
from joyfly.types import StickCommand
from sitl_emu.testing.sim import Sim

KEY = hashlib.sha256(b"joyfly signing").digest()


@pytest.fixture
def sim() -> Iterator[Sim]:
    with Sim() as s:
        yield s


def _session(sim: Sim, key: bytes | None, setup: bool = False) -> FlightSession:
    link = VehicleLink(UdpTransport(("127.0.0.1", 0), sim.ports(0).api), sim.clock)
    if key is not None:
        link.use_signing(key, setup=setup)
    return FlightSession(link, TimedSticks(sim.clock, [(0.0, StickCommand())]), sim.clock, SessionSettings())


def _run(session: FlightSession, sim: Sim, seconds: float) -> None:
    end = sim.clock.now() + seconds
    while not session.finished and sim.clock.now() < end:
        session.run_once()
    session.link.close()


def test_with_the_key_joyfly_flies_a_signing_vehicle(sim: Sim) -> None:
    sim.nodes[0].signing.provision(KEY)
    session = _session(sim, KEY)
    _run(session, sim, 12.0)
    assert session.phase is Phase.FLYING, "\n".join(n.text for n in session.notes)
    assert sim.nodes[0].api.stats.rx_signing_rejected == 0


def test_without_the_key_the_signing_vehicle_ignores_joyfly(sim: Sim) -> None:
    sim.nodes[0].signing.provision(KEY)
    session = _session(sim, None)
    _run(session, sim, 12.0)
    assert session.phase is not Phase.FLYING and not sim.vehicle(0).snapshot().armed
    assert sim.nodes[0].api.stats.rx_signing_rejected > 0


def test_setup_signing_gives_a_vehicle_without_a_key_joyflys_and_then_flies(sim: Sim) -> None:
    session = _session(sim, KEY, setup=True)
    _run(session, sim, 12.0)
    assert sim.nodes[0].signing.key == KEY
    assert session.phase is Phase.FLYING, "\n".join(n.text for n in session.notes)


@pytest.mark.parametrize(("args", "words"), [
    (["--setup-signing"], "name its file with --signing-key"),
    (["--signing-key", "/nonexistent/key"], "cannot read it"),
])
def test_signing_option_mistakes_are_one_sentence(args: list[str], words: str) -> None:
    result = CliRunner().invoke(main, ["fly", *args])
    assert result.exit_code != 0 and words in result.output
    assert "Traceback" not in result.output
