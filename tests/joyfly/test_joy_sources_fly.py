"""`joyfly fly --joy X` end to end, as a user runs it (issue 10.1, 10.2, 10.13): what is not a joystick is refused at
open with one sentence, before any MAVLink is sent, so nothing arms; a --record recording, a raw event stream named
with raw: and the example script fly.

A real vehicle (sitl_emu's node, in-process on free loopback ports) listens where joyfly sends: the refusals must
leave it unarmed and without a single datagram from joyfly; the flights prove the same harness sees an arm.
"""

from __future__ import annotations

import os
import random
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest
from support import REPO_ROOT
from support.ports import free_udp_port

from joyfly.demo import EmbeddedVehicle
from joyfly.sticks.js.reader import JS_EVENT_AXIS, JS_EVENT_BUTTON, JS_EVENT_INIT, pack_event
from joyfly.sticks.virtual import JoyRecorder
from joyfly.types import JoyState

SPEED = 4.0
ROOT = REPO_ROOT
REFUSE_WALL_S = 15.0  # a refusal takes a Python start-up (about 1 s); before the fix joyfly armed and hovered


@dataclass
class Vehicle:
    emulator: EmbeddedVehicle
    joy_port: int

    @property
    def url(self) -> str:
        host, port = self.emulator.api_address
        return f"udp://127.0.0.1:{self.joy_port}@{host}:{port}"

    @property
    def armed(self) -> bool:
        return bool(self.emulator.node.vehicle.snapshot().armed)

    @property
    def datagrams_heard(self) -> int:
        return int(self.emulator.node.api.link.stats.rx_datagrams)


@pytest.fixture
def vehicle() -> Iterator[Vehicle]:
    joy_port = free_udp_port()
    emulator = EmbeddedVehicle(joy_port, SPEED)
    # the Position-mode flights stream MANUAL_CONTROL: 3 s before PX4 takes it for lost (PX4: 0.5 s, an eighth of a
    # second of wall time at x4) keeps a busy machine from starving it into an RC-loss failsafe
    emulator.node.vehicle.params.set("COM_RC_LOSS_T", 3.0)
    emulator.start()
    try:
        yield Vehicle(emulator, joy_port)
    finally:
        emulator.stop()


@dataclass
class Run:
    returncode: int
    stopped: bool  # still running when the test stopped it (Ctrl-C)
    stdout: str
    stderr: str
    armed: bool


def start(vehicle: Vehicle, spec: str, *extra: str) -> subprocess.Popen[str]:
    return subprocess.Popen([sys.executable, "-m", "joyfly", "fly", "--joy", spec, "--url", vehicle.url,
                             "--speed", str(SPEED), "--connect-timeout", "60", *extra], cwd=ROOT,
                            stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def fly(vehicle: Vehicle, spec: str, wall_s: float = REFUSE_WALL_S) -> Run:
    """`joyfly fly --joy spec` against the vehicle until it exits, the vehicle arms, or wall_s passes."""
    proc = start(vehicle, spec)
    armed = False
    end = time.monotonic() + wall_s
    while proc.poll() is None and time.monotonic() < end and not armed:
        armed = vehicle.armed
        time.sleep(0.02)
    stopped = proc.poll() is None
    if stopped:
        proc.send_signal(signal.SIGINT)
    try:
        stdout, stderr = proc.communicate(timeout=20.0)
    except subprocess.TimeoutExpired:
        proc.kill()
        stdout, stderr = proc.communicate()
    return Run(proc.returncode, stopped, stdout, stderr, armed or vehicle.armed)


def assert_refused(run: Run, vehicle: Vehicle, *fragments: str) -> None:
    assert not run.armed, "the vehicle armed:\n" + run.stdout + run.stderr
    assert run.returncode == 2 and not run.stopped, f"exit {run.returncode}:\n{run.stdout}{run.stderr}"
    lines = run.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("joyfly: "), run.stderr  # one sentence, no traceback
    assert lines[0].endswith(".") and lines[0].count(". ") == 0, lines[0]
    for fragment in fragments:
        assert fragment in lines[0], lines[0]
    assert vehicle.datagrams_heard == 0  # refused before any MAVLink was sent


def test_a_text_file_never_arms_the_vehicle(vehicle: Vehicle, tmp_path: Path) -> None:
    notes = tmp_path / "notes.txt"
    notes.write_text("Flight notes\n- take off at the field\n- try the fence at 5 m\n")
    assert_refused(fly(vehicle, str(notes)), vehicle, str(notes), "not a joyfly recording", f"raw:{notes}")


def test_a_random_binary_file_never_arms_the_vehicle(vehicle: Vehicle, tmp_path: Path) -> None:
    blob = tmp_path / "firmware.bin"
    blob.write_bytes(random.Random(10).randbytes(4096))
    assert_refused(fly(vehicle, str(blob)), vehicle, str(blob), f"raw:{blob}")


def test_a_file_of_js_events_not_named_raw_is_refused_too(vehicle: Vehicle, tmp_path: Path) -> None:
    """Even well-formed records: only the user can say a regular file is a joystick (raw:), joyfly cannot tell."""
    events = tmp_path / "events.bin"
    events.write_bytes(pack_event(JS_EVENT_AXIS, 1, -32767) * 64)
    assert_refused(fly(vehicle, str(events)), vehicle, f"raw:{events}")


def test_a_directory_fails_at_once(vehicle: Vehicle, tmp_path: Path) -> None:
    assert_refused(fly(vehicle, str(tmp_path)), vehicle, f"{tmp_path} is a directory")


def test_dev_null_fails_at_once(vehicle: Vehicle) -> None:
    assert_refused(fly(vehicle, "/dev/null"), vehicle, "/dev/null", "not a joystick")


def _at_rest_events(span_s: float = 60.0) -> bytes:
    """A capture of the script profile's layout at rest for span_s: what the kernel sends on open (7 buttons up,
    4 axes centred), then axis 0 reported centred every 0.5 s (a capture lasts until its last record)."""
    moves = [pack_event(JS_EVENT_AXIS, 0, 0, time_ms=500 * k) for k in range(1, int(span_s * 2) + 1)]
    return b"".join([pack_event(JS_EVENT_BUTTON | JS_EVENT_INIT, i, 0) for i in range(7)]
                    + [pack_event(JS_EVENT_AXIS | JS_EVENT_INIT, i, 0) for i in range(4)] + moves)


def _recording(path: Path) -> None:
    """A --record recording of a joystick at rest for 60 s, under the script profile's device name."""
    recorder = JoyRecorder(str(path), "joyfly script", "/dev/input/js0")
    recorder.record(JoyState(0.0, (0, 0, 0, 0), (0,) * 7))
    recorder.record(JoyState(60.0, (0, 0, 0, 0), (0,) * 7))
    recorder.close()


@pytest.mark.parametrize("kind", ["raw", "recording", "replay"])
@pytest.mark.slow
def test_a_raw_stream_named_as_such_and_a_recording_do_fly(vehicle: Vehicle, tmp_path: Path, kind: str) -> None:
    path = tmp_path / ("events.bin" if kind == "raw" else "session.jsonl")
    if kind == "raw":
        path.write_bytes(_at_rest_events())
    else:
        _recording(path)
    spec = {"raw": f"raw:{path}", "recording": str(path), "replay": f"replay:{path}"}[kind]
    run = fly(vehicle, spec, wall_s=40.0)
    assert run.armed, f"exit {run.returncode}:\n{run.stdout}{run.stderr}"
    assert "Traceback" not in run.stderr
    name = str(path) if kind == "raw" else "joyfly script"  # raw records: the path; a recording: its device's name
    assert f"joystick {name} ({path})" in run.stdout, run.stdout


def test_random_bytes_as_a_raw_capture_never_arm_the_vehicle(vehicle: Vehicle, tmp_path: Path) -> None:
    """Issue 25.1: 4 kB of random bytes given as raw:FILE armed, took off and hovered for minutes; the records are
    now checked at open, so joyfly refuses the file in one sentence before it sends any MAVLink."""
    blob = tmp_path / "rand.bin"
    blob.write_bytes(random.Random(25).randbytes(4096))
    assert_refused(fly(vehicle, f"raw:{blob}"), vehicle, f"raw:{blob} is not a joystick capture", "record 1")


def test_random_bytes_through_a_fifo_never_arm_the_vehicle(vehicle: Vehicle, tmp_path: Path) -> None:
    """A FIFO is checked record by record as it arrives: bytes that are no js_events end joyfly before it arms, a
    joystick mistake (exit status 2, as raw: garbage and README's exit statuses)."""
    fifo = tmp_path / "js0"
    os.mkfifo(fifo)
    proc = start(vehicle, str(fifo))
    writer = os.open(fifo, os.O_WRONLY)  # blocks until joyfly opened its end
    try:
        os.write(writer, random.Random(7).randbytes(4096))
        stdout, stderr = proc.communicate(timeout=60.0)
    finally:
        os.close(writer)
        proc.kill()
    assert proc.returncode == 2 and not vehicle.armed, stdout + stderr
    lines = stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"joyfly: {fifo} sends something other than js_event records")
    assert "Armed" not in stdout


@pytest.mark.slow
def test_a_raw_capture_that_ends_in_flight_holds_then_lands(vehicle: Vehicle, tmp_path: Path) -> None:
    """A capture's end is a joystick that went away: hold, then land after --joy-timeout; joyfly then ends."""
    capture = tmp_path / "events.bin"
    capture.write_bytes(_at_rest_events(span_s=25.0))
    proc = subprocess.Popen([sys.executable, "-m", "joyfly", "fly", "--joy", f"raw:{capture}", "--url", vehicle.url,
                             "--speed", str(SPEED), "--joy-timeout", "3"], cwd=ROOT, stdin=subprocess.DEVNULL,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    armed = False
    end = time.monotonic() + 90.0
    while proc.poll() is None and time.monotonic() < end:
        armed |= vehicle.armed
        time.sleep(0.05)
    if proc.poll() is None:
        proc.send_signal(signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=30.0)
    assert armed and proc.returncode == 0 and not vehicle.armed, stdout + stderr
    assert "OFFBOARD: you have control" in stdout and "reached its end (its records span 25.0 s)" in stdout
    assert "Joystick lost: holding position" in stdout and "Joystick still lost after 3 s: landing." in stdout
    assert "Landed and disarmed" in stdout and "The joystick is gone" in stdout


@pytest.mark.slow
def test_a_fifo_still_waits_for_its_writer(vehicle: Vehicle, tmp_path: Path) -> None:
    fifo = tmp_path / "js0"
    os.mkfifo(fifo)
    run = fly(vehicle, str(fifo), wall_s=4.0)
    assert run.stopped and not run.armed, run.stdout + run.stderr  # still waiting when stopped, nothing flew
    assert "Waiting for the joystick" in run.stdout


@pytest.mark.slow
def test_the_example_script_flies_and_lands(vehicle: Vehicle) -> None:
    """examples/joystick_script.txt as its first line says to run it: joyfly takes off by itself, the script flies
    the square and the fence push, presses LAND, and the vehicle ends landed and disarmed."""
    proc = start(vehicle, "script:examples/joystick_script.txt")
    assert proc.stdout is not None
    seen: list[str] = []
    end = time.monotonic() + 90.0  # about 45 simulated seconds at x4, with room for a busy machine
    while time.monotonic() < end and proc.poll() is None and not any("Landed and disarmed" in ln for ln in seen):
        seen.append(proc.stdout.readline())
    proc.send_signal(signal.SIGINT)
    try:
        stdout, stderr = proc.communicate(timeout=20.0)
    finally:
        proc.kill()
    out = "".join(seen) + stdout
    assert proc.returncode == 0 and not vehicle.armed, out + stderr
    assert "OFFBOARD: you have control" in out and "LAND pressed: landing" in out and "Landed and disarmed" in out
    assert not any(f"{button} pressed" in out for button in ("ARM", "TAKEOFF", "OFFBOARD"))
    distance = next(line for line in out.splitlines() if line.startswith("distance flown"))
    assert float(distance.split()[2]) > 25.0  # climb, the square, the fence push and back


def _fly_to_the_end(vehicle: Vehicle, spec: str, *extra: str, wall_s: float = 90.0) -> tuple[int | None, str, bool]:
    """`joyfly fly` until it ends by itself (or wall_s: then Ctrl-C); (exit status, output, whether it ever armed)."""
    proc = start(vehicle, spec, *extra)
    armed = False
    end = time.monotonic() + wall_s
    while proc.poll() is None and time.monotonic() < end:
        armed |= vehicle.armed
        time.sleep(0.05)
    if proc.poll() is None:
        proc.send_signal(signal.SIGINT)
    try:
        stdout, stderr = proc.communicate(timeout=30.0)
    finally:
        proc.kill()
    return proc.returncode, stdout + stderr, armed


@pytest.mark.slow
def test_the_position_mode_example_script_takes_off_flies_and_lands(vehicle: Vehicle) -> None:
    """Issue 25.8: the README's script has no throttle in time, so in Position mode it never left the ground; the
    example for Position mode takes off with the throttle, flies its square and lands, without a warning."""
    status, out, armed = _fly_to_the_end(vehicle, "script:examples/joystick_script_position.txt",
                                         "--control", "position")
    assert status == 0 and armed and not vehicle.armed, out
    assert "Takeoff detected" in out and "LAND pressed: landing" in out and "Landed and disarmed" in out, out
    assert "not take off" not in out and "cannot take off" not in out  # no warning at the start
    distance = next(line for line in out.splitlines() if line.startswith("distance flown"))
    assert float(distance.split()[2]) > 8.0, out  # the climb and the square


@pytest.mark.slow
def test_position_mode_with_a_script_that_never_takes_off_in_time_warns_at_start(vehicle: Vehicle) -> None:
    proc = start(vehicle, "script:examples/joystick_script.txt", "--control", "position")
    assert proc.stdout is not None
    first = [proc.stdout.readline() for _ in range(2)]
    proc.send_signal(signal.SIGINT)
    try:
        stdout, stderr = proc.communicate(timeout=30.0)
    finally:
        proc.kill()
    warning = first[1]
    assert "examples/joystick_script.txt first pushes the throttle up at 20 s" in warning, [*first, stdout, stderr]
    assert "will likely not take off" in warning and "examples/joystick_script_position.txt" in warning


@pytest.mark.slow
def test_a_second_joyfly_on_another_port_is_told_the_vehicle_is_busy(vehicle: Vehicle) -> None:
    """Issue 25.9: the vehicle answers its first client only (PX4's API link); a second joyfly used to be told to
    start a vehicle."""
    first = start(vehicle, "script:examples/joystick_script.txt")
    try:
        end = time.monotonic() + 40.0
        while not vehicle.armed and time.monotonic() < end:
            time.sleep(0.05)
        assert vehicle.armed
        other = f"udp://127.0.0.1:{free_udp_port()}@{vehicle.url.rsplit('@', 1)[1]}"
        second = subprocess.run([sys.executable, "-m", "joyfly", "fly", "--joy", "script:examples/joystick_script.txt",
                                 "--url", other, "--speed", str(SPEED), "--connect-timeout", "4"], cwd=ROOT,
                                stdin=subprocess.DEVNULL, capture_output=True, text=True, timeout=60)
    finally:
        first.send_signal(signal.SIGINT)
        first.communicate(timeout=60.0)
    lines = second.stderr.splitlines()
    assert second.returncode == 1 and len(lines) == 1, second.stdout + second.stderr
    assert "the vehicle is probably busy with another client" in lines[0] and "sitl-emu serve`" not in lines[0]
