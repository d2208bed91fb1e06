"""Missions from a user's test: the scripted client's helpers (sitl_emu.testing.mission_client) against a lockstep
Sim, and examples/mission_pymavlink.py against a Sim running in the background (wall clock: the example is a plain
pymavlink script)."""

from __future__ import annotations

import importlib.util
import socket
from pathlib import Path
from typing import Any

import pytest

from sitl_emu.testing.client import FlightClient
from sitl_emu.testing.mission_client import (
    return_to_launch,
    start_mission,
    takeoff,
    upload_mission,
    wait_reached,
    waypoint,
)
from sitl_emu.testing.sim import Sim

pytestmark = pytest.mark.slow  # processes or long flights: not in `make test-fast`

EXAMPLE = Path(__file__).parents[3] / "examples" / "mission_pymavlink.py"


def test_upload_start_and_wait_for_each_item() -> None:
    with Sim() as sim:
        client = FlightClient(sim.ports(0).api, sim.clock)
        client.wait(lambda: client.healthy, 30.0, "health")
        home = sim.vehicle(0).ref.lat_deg, sim.vehicle(0).ref.lon_deg
        items = [takeoff(home, 5.0), waypoint(home, 15.0, 0.0, 5.0), waypoint(home, 15.0, 15.0, 6.0),
                 return_to_launch()]
        upload_mission(client, items)
        assert sim.vehicle(0).mission_store().count(0) == 4
        start_mission(client)
        wait_reached(client, 1, 60.0)
        assert client.seen.reached == [0, 1] and client.seen.mission_current.seq == 2
        wait_reached(client, 2, 60.0)
        # item 2 and the RTL item complete in one navigator cycle: only the latest is reported (as PX4 does)
        assert client.seen.reached == [0, 1, 3] and client.seen.mission_current.mission_state == 5  # COMPLETE
        client.wait(lambda: not client.armed, 90.0, "return, landing and disarm")
        # after disarming: Hold, which the commander made the user's mode when the mission finished (as recorded
        # from PX4, px4-mission cases.json flight1.sequence)
        assert client.seen.modes[-2:] == ["AUTO.RTL", "AUTO.LOITER"]
        client.close()


def _free_udp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _load_example() -> Any:
    spec = importlib.util.spec_from_file_location("mission_pymavlink", EXAMPLE)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_pymavlink_example_flies_its_mission(capsys: pytest.CaptureFixture[str]) -> None:
    port = _free_udp_port()
    with Sim(api_remote=("127.0.0.1", port)) as sim:
        sim.start(speed=8.0)  # the example reads with pymavlink's small UDP buffer: faster would drop telemetry
        assert _load_example().main(["--url", f"udpin:127.0.0.1:{port}", "--timeout", "60"]) == 0
    out = capsys.readouterr().out
    assert "uploaded 4 items" in out
    assert out.index("reached item 1 of 4") < out.index("reached item 3 of 4") < out.index("landed and disarmed")
    assert "vehicle: " in out  # texts reach it (which ones: UDP may drop a datagram under load)
