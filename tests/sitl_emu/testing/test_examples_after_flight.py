"""The bundled pymavlink examples on a vehicle that flew before: after an OFFBOARD flight PX4 (and the emulator)
stays disarmed in OFFBOARD with HEARTBEAT system_status UNINIT (HEARTBEAT.hpp: STANDBY only when the arming checks
pass in the current mode; /work/shared/reference/px4-recorded-facts.md section 5), and an example that waited for
STANDBY waited forever. Each example now switches such a vehicle to Hold and flies to the end."""

from __future__ import annotations

import importlib.util
import socket
import threading
from pathlib import Path
from typing import Any

import pytest

from sitl_emu.px4 import MavState, NavState
from sitl_emu.testing.client import FlightClient, fly_square
from sitl_emu.testing.sim import Sim

pytestmark = pytest.mark.slow  # processes or long flights: not in `make test-fast`

EXAMPLES = Path(__file__).parents[3] / "examples"
SPEED = 8.0  # the examples read with pymavlink's small UDP buffer: faster would drop telemetry


def _free_udp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _load(name: str) -> Any:
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _fly_offboard_first(sim: Sim, port: int) -> None:
    """An OFFBOARD flight (take off, square, land) from the address the example listens on, in lockstep."""
    client = FlightClient(sim.ports(0).api, sim.clock)
    client.sock.close()  # the vehicle's API link latches its first peer: be that peer, on the example's port
    client.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    client.sock.bind(("127.0.0.1", port))
    client.sock.setblocking(False)
    try:
        result = fly_square(client, side_m=2.0)
        assert result.ok, result.error
        client.spin(2.0)
        heartbeat = client.seen.heartbeat
        assert not client.armed and client.in_mode(NavState.OFFBOARD), client.seen.modes
        assert heartbeat.system_status == MavState.UNINIT  # PX4's: OFFBOARD without setpoints cannot arm
    finally:
        client.close()


def _run(main: Any, argv: list[str], limit_s: float) -> int:
    """The example's main() in a thread: its exit status, or a failure if it does not end within `limit_s`."""
    outcome: list[Any] = []

    def run() -> None:
        try:
            outcome.append(main(argv))
        except SystemExit as exit_:
            outcome.append(exit_.code)

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    thread.join(limit_s)
    assert outcome, f"the example did not finish within {limit_s:g} s"
    return int(outcome[0] or 0)


@pytest.mark.parametrize("example", ["pymavlink_offboard", "mission_pymavlink"])
def test_an_example_flies_a_vehicle_that_flew_offboard_before(example: str, capsys: pytest.CaptureFixture[str]) -> None:
    port = _free_udp_port()
    with Sim(api_remote=("127.0.0.1", port)) as sim:
        _fly_offboard_first(sim, port)
        sim.start(speed=SPEED)
        argv = ["--url", f"udpin:127.0.0.1:{port}"]
        argv += ["--speed", str(SPEED)] if example == "pymavlink_offboard" else ["--timeout", "60"]
        assert _run(_load(example).main, argv, 90.0) == 0
    out = capsys.readouterr().out
    assert "disarmed in OFFBOARD, where it cannot arm: switching to Hold" in out
    assert out.rstrip().endswith("landed and disarmed")


@pytest.mark.parametrize("example", ["pymavlink_offboard", "mission_pymavlink"])
def test_an_example_that_waits_in_vain_says_what_it_waited_for(example: str) -> None:
    from pymavlink import mavutil

    port = _free_udp_port()
    with Sim(api_remote=("127.0.0.1", port)):  # never stepped: no HEARTBEAT comes
        mav = mavutil.mavlink_connection(f"udpin:127.0.0.1:{port}", source_system=255, source_component=190)
        try:
            with pytest.raises(SystemExit) as stopped:
                _load(example).wait_ready(mav, 0.5)
        finally:
            mav.close()
    assert str(stopped.value.code) == ("the vehicle was not ready to arm (HEARTBEAT system_status 3, STANDBY) within "
                                       "0.5 s; last seen: no HEARTBEAT. Is it armed, or are its pre-flight checks "
                                       "failing?")
