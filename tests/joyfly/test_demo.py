"""`joyfly demo`: a whole scripted flight against the built-in emulator, ending with a summary, with or without a
terminal (CI), and against a vehicle already listening at --url."""

from __future__ import annotations

import io
import re
import socket
import subprocess
import sys

import pytest
from support import REPO_ROOT

from flightview.server import install_hint
from joyfly.demo import DemoError, EmbeddedVehicle, run_demo

SPEED = 10.0  # the built-in emulator: joyfly reads its simulated clock, so timeouts stay in step when slow
# A vehicle already listening runs on the wall clock at a speed factor; PX4's 1 s offboard-loss window is 1/speed s
# of wall time, so keep that factor low enough that a busy CI machine cannot starve it into a real failsafe.
URL_SPEED = 4.0


@pytest.mark.slow
def test_demo_flies_the_script_and_ends_with_a_summary() -> None:
    out = io.StringIO()
    assert run_demo(speed=SPEED, live=False, out=out) == 0
    text = out.getvalue()
    assert "OFFBOARD: you have control" in text
    assert "LAND pressed: landing" in text and "Landed and disarmed" in text
    assert "distance flown" in text and "time in OFFBOARD" in text
    closest = next(line for line in text.splitlines() if line.startswith("closest to the fence"))
    assert "inside" in closest or float(closest.split()[4]) <= 0.5  # the fence push stops at the fence
    distance = next(line for line in text.splitlines() if line.startswith("distance flown"))
    assert float(distance.split()[2]) > 20.0  # climb + square + fence push + return


@pytest.mark.slow
def test_demo_runs_without_a_terminal_as_in_ci() -> None:
    proc = subprocess.run([sys.executable, "-m", "joyfly", "demo", "--speed", str(SPEED)], stdin=subprocess.DEVNULL,
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "time in OFFBOARD" in proc.stdout and "\x1b[" not in proc.stdout
    assert "Traceback" not in proc.stderr


@pytest.mark.slow
def test_demo_flies_a_vehicle_already_listening_at_url() -> None:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        probe.bind(("127.0.0.1", 0))
        joy_port = probe.getsockname()[1]
    vehicle = EmbeddedVehicle(joy_port, URL_SPEED)
    vehicle.start()
    try:
        host, port = vehicle.api_address
        out = io.StringIO()
        assert run_demo(url=f"udp://127.0.0.1:{joy_port}@{host}:{port}", speed=URL_SPEED, live=False, out=out) == 0
    finally:
        vehicle.stop()
    assert "Landed and disarmed" in out.getvalue()


@pytest.mark.slow
def test_demo_in_position_mode_takes_off_with_the_throttle_and_stays_inside_the_fence() -> None:
    # PX4 takes MANUAL_CONTROL for lost 0.5 s (simulated) after the last one: 50 ms of wall time at x10, which a busy
    # CI machine can take from the process (joyfly and the emulator share it here); at x4 it is 125 ms
    out = io.StringIO()
    assert run_demo(speed=URL_SPEED, live=False, out=out, control="position") == 0, out.getvalue()
    text = out.getvalue()
    assert "Armed in Position mode" in text and "Vehicle: Takeoff detected" in text, text
    assert "LAND pressed: landing" in text and "Landed and disarmed" in text, text
    assert "time in POSCTL" in text and "Position mode (POSCTL), MANUAL_CONTROL at 25 Hz" in text
    closest = next(line for line in text.splitlines() if line.startswith("closest to the fence"))
    assert "inside" in closest  # the full stick north stops at the fence
    distance = next(line for line in text.splitlines() if line.startswith("distance flown"))
    assert float(distance.split()[2]) > 15.0  # climb + square + fence push


@pytest.mark.slow
def test_demo_flies_in_wind_and_lands() -> None:
    out = io.StringIO()
    status = run_demo(speed=SPEED, live=False, out=out, wind="5@270,light")
    text = out.getvalue()
    assert "wind 5@270,light" in text.splitlines()[0]
    assert "Landed and disarmed" in text
    # PX4 takes off with at most MPC_TILTMAX_LND (12 deg) of tilt: 5 m/s carries it out of the 5 m fence, and back
    assert status == 3 and "fence breached" in text, text


def test_demo_wind_reaches_the_built_in_emulator() -> None:
    vehicle = EmbeddedVehicle(0, 1.0, "5@270")
    try:
        assert vehicle.node.vehicle.faults.wind is not None
    finally:
        vehicle.close()


@pytest.mark.parametrize(("kwargs", "said"), [
    ({"wind": "5@999"}, "--wind: wind '5@999': the direction it blows from is in degrees, -360 to 360"),
    ({"wind": "5@270", "url": "udp://127.0.0.1:14540@127.0.0.1:14557"}, "--wind blows on the built-in emulator only"),
    ({"gcs_remote": "127.0.0.1:14550", "url": "udp://127.0.0.1:14540@127.0.0.1:14557"},
     "--gcs-remote sets the built-in emulator's ground-station link only"),
    ({"gcs_remote": "127.0.0.1:99999"}, "--gcs-remote"),
])
def test_demo_refuses_bad_wind_in_one_sentence(kwargs: dict[str, str], said: str) -> None:
    with pytest.raises(DemoError, match="^" + re.escape(said)):
        run_demo(live=False, out=io.StringIO(), **kwargs)  # type: ignore[arg-type]


@pytest.mark.slow
def test_demo_cli_bad_wind_exits_2() -> None:
    proc = subprocess.run([sys.executable, "-m", "joyfly", "demo", "--wind", "north"], stdin=subprocess.DEVNULL,
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2 and "--wind" in proc.stderr and "Traceback" not in proc.stderr, proc.stderr


def test_the_demo_sends_no_ground_station_telemetry_to_14550_unless_asked() -> None:
    """A QGroundControl on this machine (UDP 14550) sees nothing of the demo by default: the ground-station link
    sends to a socket of the demo's own until a ground station talks to its port."""
    vehicle = EmbeddedVehicle(0, 1.0)
    try:
        assert vehicle.node.gcs.link.remote != ("127.0.0.1", 14550)
        assert vehicle.gcs_remote is None
        assert vehicle.describe_gcs().startswith(f"ground-station link on UDP {vehicle.gcs_port}, sending nowhere")
    finally:
        vehicle.close()


@pytest.mark.slow
def test_gcs_remote_sends_the_telemetry_there_and_the_demo_says_how_to_get_the_view(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "rerun", None)  # as without the view extra, which the demo does not need
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as gcs:
        gcs.bind(("127.0.0.1", 0))
        gcs.settimeout(30)
        port = gcs.getsockname()[1]
        out = io.StringIO()
        assert run_demo(speed=SPEED, live=False, out=out, gcs_remote=f"127.0.0.1:{port}") == 0, out.getvalue()
        data = gcs.recv(65535)
    assert data[:1] == b"\xfd"  # MAVLink 2 from the ground-station link
    lines = out.getvalue().splitlines()
    assert lines[1].startswith("joyfly demo: ground-station link on UDP ")
    assert lines[1].endswith(f"sending to 127.0.0.1:{port}")
    assert lines[2] == f"joyfly demo: to see the flight in 3D in a browser, {install_hint()} and add --view"
    assert install_hint() == f"{sys.executable} -m pip install -e '{REPO_ROOT}[view]'"  # README's, from this clone
