"""End to end over loopback UDP: sitl_emu's vehicle node (in-process, or `sitl-emu serve` as a subprocess) and
joyfly's flight session reading a FIFO joystick of js_event records, as a user would wire them.

The emulator runs faster than real time (its runner's speed factor) and joyfly's clock is the vehicle's simulated
time, so the flights take a few wall-clock seconds each and stay in step on a busy machine.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest
from support import REPO_ROOT
from support.ports import free_udp_port, free_udp_ports

from joyfly.demo import EmbeddedVehicle, VehicleTimeClock
from joyfly.link.transport import UdpTransport
from joyfly.link.vehicle_link import VehicleLink
from joyfly.session.flight_session import FlightSession, Phase, SessionSettings
from joyfly.sticks.js.reader import JS_EVENT_AXIS, JS_EVENT_BUTTON, JS_EVENT_INIT, pack_event
from joyfly.sticks.mapping import open_sticks

pytestmark = pytest.mark.slow  # processes or long flights: not in `make test-fast`

SPEED = 8.0
AXIS_FULL = 32767


@dataclass
class Flight:
    clock: VehicleTimeClock
    session: FlightSession
    fifo_fd: int
    emulator: EmbeddedVehicle
    thread: threading.Thread
    max_abs_xy: list[float] = field(default_factory=lambda: [0.0])

    def stick(self, axis: int, value: float) -> None:
        os.write(self.fifo_fd, pack_event(JS_EVENT_AXIS, axis, round(value * AXIS_FULL)))

    def button(self, index: int, down: bool) -> None:
        os.write(self.fifo_fd, pack_event(JS_EVENT_BUTTON, index, int(down)))

    def wait(self, sim_s: float) -> None:
        end = self.clock.now() + sim_s
        while self.clock.now() < end:
            time.sleep(0.01)
            self._track()

    def wait_for(self, phase: Phase, sim_s: float) -> None:
        end = self.clock.now() + sim_s
        while self.session.phase is not phase and self.clock.now() < end:
            time.sleep(0.01)
            self._track()
        assert self.session.phase is phase, "\n".join(n.text for n in self.session.notes)

    def _track(self) -> None:
        pos = self.session.link.state.pos_ned_m
        if pos is not None:
            self.max_abs_xy[0] = max(self.max_abs_xy[0], abs(pos[0]), abs(pos[1]))

    def pos(self) -> tuple[float, float, float]:
        pos = self.session.link.state.pos_ned_m
        assert pos is not None
        return pos


@pytest.fixture
def flight(tmp_path: Path) -> Iterator[Flight]:
    fifo = tmp_path / "js0"
    os.mkfifo(fifo)
    transport = UdpTransport(("127.0.0.1", 0), None)
    emulator = EmbeddedVehicle(transport.local_port, SPEED)
    transport.remote = emulator.api_address
    emulator.start()
    clock = emulator.clock()  # joyfly runs on the vehicle's simulated time
    sticks = open_sticks(str(fifo), clock, profile="script")  # axes forward, right, up, yaw; buttons arm.. offboard
    fd = os.open(fifo, os.O_WRONLY | os.O_NONBLOCK)
    for index in range(7):
        os.write(fd, pack_event(JS_EVENT_BUTTON | JS_EVENT_INIT, index, 0))
    for index in range(4):
        os.write(fd, pack_event(JS_EVENT_AXIS | JS_EVENT_INIT, index, 0))
    settings = SessionSettings(joy_timeout_s=5.0, fence_m=5.0)
    session = FlightSession(VehicleLink(transport, clock), sticks, clock, settings)
    thread = threading.Thread(target=session.run, daemon=True)
    thread.start()
    f = Flight(clock, session, fd, emulator, thread)
    try:
        f.wait_for(Phase.FLYING, 20.0)
        f.wait(6.0)  # finish the climb to --alt
        yield f
    finally:
        session.abort()  # landing on exit is the SIGINT test's subject
        thread.join(5.0)
        os.close(fd)
        emulator.stop()
        session.link.close()
        sticks.close()


def test_stick_forward_flies_north_then_right_flies_east(flight: Flight) -> None:
    x0, y0, _ = flight.pos()
    flight.stick(0, 0.4)
    flight.wait(1.5)
    flight.stick(0, 0.0)
    flight.wait(3.0)
    x1, y1, _ = flight.pos()
    assert x1 - x0 > 1.5 and abs(y1 - y0) < 0.5
    flight.stick(1, 0.4)
    flight.wait(1.5)
    flight.stick(1, 0.0)
    flight.wait(3.0)
    x2, y2, _ = flight.pos()
    assert y2 - y1 > 1.5 and abs(x2 - x1) < 0.5


def test_released_sticks_hold_position(flight: Flight) -> None:
    flight.stick(0, -0.5)
    flight.stick(1, 0.3)
    flight.wait(1.0)
    flight.stick(0, 0.0)
    flight.stick(1, 0.0)
    flight.wait(3.0)
    settled = flight.pos()
    flight.wait(8.0)
    assert max(abs(a - b) for a, b in zip(flight.pos(), settled, strict=True)) < 0.5


def test_pushing_against_the_fence_stops_at_it(flight: Flight) -> None:
    flight.stick(0, 1.0)
    flight.wait(6.0)
    flight.stick(1, -1.0)
    flight.wait(6.0)
    flight.stick(0, 0.0)
    flight.stick(1, 0.0)
    flight.wait(2.0)
    assert 4.0 < flight.max_abs_xy[0] <= 5.0 + 0.5
    x, y, _ = flight.pos()
    assert x > 4.0 and y < -4.0


def test_closing_the_fifo_holds_then_lands_after_the_timeout(flight: Flight) -> None:
    flight.stick(0, 0.4)
    flight.wait(0.5)
    os.close(flight.fifo_fd)
    flight.fifo_fd = os.open("/dev/null", os.O_WRONLY)  # for the fixture's cleanup
    flight.wait(1.0)
    assert any("Joystick lost" in n.text for n in flight.session.notes)
    held = flight.pos()
    flight.wait(2.5)
    assert flight.session.phase is Phase.FLYING
    assert max(abs(a - b) for a, b in zip(flight.pos(), held, strict=True)) < 0.5
    flight.wait_for(Phase.LANDING, 3.0)
    flight.wait_for(Phase.DONE, 30.0)  # landed, disarmed and no joystick: nothing more to fly
    assert not flight.session.link.state.armed
    assert any("The joystick is gone" in n.text for n in flight.session.notes)




def _serve(cwd: Path, joy_port: int, emu_port: int, gcs_port: int, speed: str) -> subprocess.Popen[bytes]:
    """In `cwd` (tmp_path), where it writes its parameters file and flight logs."""
    return subprocess.Popen([sys.executable, "-m", "sitl_emu", "serve", "--port", str(emu_port), "--remote",
                             f"127.0.0.1:{joy_port}", "--gcs-port", str(gcs_port), "--speed", speed, "--no-console"],
                            cwd=cwd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)


Procs = tuple[subprocess.Popen[bytes], subprocess.Popen[str], str]


def _start_pair(tmp_path: Path, speed: str = "4", script_text: str = "0 forward=0\n+60 end\n",
                ports: tuple[int, int, int] | None = None) -> Procs:
    """`sitl-emu serve` and `joyfly fly` (on a script joystick) as a user runs them, flying in OFFBOARD."""
    joy_port, emu_port, gcs_port = ports or free_udp_ports(3)
    emu = _serve(tmp_path, joy_port, emu_port, gcs_port, speed)
    script = tmp_path / "hover.txt"
    script.write_text(script_text)
    joy = subprocess.Popen([sys.executable, "-m", "joyfly", "fly", "--joy", f"script:{script}", "--url",
                            f"udp://127.0.0.1:{joy_port}@127.0.0.1:{emu_port}", "--speed", speed],
                           stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        out = _read_until(joy, "OFFBOARD: you have control", 30.0)
    except BaseException:
        _kill(joy, emu)
        raise
    return emu, joy, out


def _kill(*procs: subprocess.Popen[Any]) -> None:
    for proc in procs:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def test_sigint_lands_disarms_and_exits_0(tmp_path: Path) -> None:
    """Ctrl-C to joyfly: it performs --on-exit land, waits until landed and disarmed, exits 0."""
    emu, joy, out = _start_pair(tmp_path)
    try:
        time.sleep(1.0)
        joy.send_signal(signal.SIGINT)
        stdout, stderr = joy.communicate(timeout=40.0)
    finally:
        _kill(joy, emu)
    out += stdout
    assert joy.returncode == 0, out + stderr
    assert "Exiting: land" in out and "Landed and disarmed" in out
    assert "Traceback" not in stderr


def test_second_sigint_quits_at_once(tmp_path: Path) -> None:
    emu, joy, _ = _start_pair(tmp_path)
    try:
        time.sleep(1.5)  # in the air (6 s at x4): on the ground the first Ctrl-C disarms at once (issue 25.6)
        joy.send_signal(signal.SIGINT)
        time.sleep(0.5)
        start = time.monotonic()
        joy.send_signal(signal.SIGINT)
        stdout, stderr = joy.communicate(timeout=10.0)
        quit_s = time.monotonic() - start
    finally:
        _kill(joy, emu)
    assert joy.returncode == 130 and quit_s < 2.0
    assert "Traceback" not in stderr
    assert stderr.count("interrupted twice") == 1 and "interrupted twice" not in stdout
    assert "the vehicle was left armed in AUTO.LAND: it lands and disarms by itself." in stderr


def test_a_script_joystick_that_ends_after_landing_exits_0_with_a_summary(tmp_path: Path) -> None:
    emu, joy, out = _start_pair(tmp_path, script_text="0 forward=0\n8 land=1\n+0.3 land=0\n+12 end\n")
    try:
        out += _read_until(joy, "highest", 60.0)  # the summary's last line, with no Ctrl-C
        joy.wait(10.0)
        assert joy.stderr is not None
        stderr = joy.stderr.read()
    finally:
        _kill(joy, emu)
    assert joy.returncode == 0, out + stderr
    assert "Landed and disarmed" in out and "The joystick is gone" in out and "joyfly is done" in out
    assert "distance flown" in out and "time in OFFBOARD" in out and "Traceback" not in stderr


def test_an_emulator_restarted_mid_flight_is_reported_as_a_restart(tmp_path: Path) -> None:
    ports = free_udp_ports(3)
    emu, joy, out = _start_pair(tmp_path, ports=ports)
    try:
        time.sleep(1.0)
        emu.kill()
        emu.wait()
        out += _read_until(joy, "Link lost", 10.0)
        time.sleep(1.0)  # 4 s of simulated time with no vehicle
        emu = _serve(tmp_path, *ports, "4")
        out += _read_until(joy, "The vehicle restarted", 20.0)
        time.sleep(0.5)
        joy.send_signal(signal.SIGINT)
        out += _read_until(joy, "highest", 20.0)  # the summary's last line (communicate() would skip the
        joy.wait(10.0)  # lines readline() buffered already)
    finally:
        _kill(joy, emu)
    assert joy.returncode == 4, out  # the flight ended in the air: not a flight that went well (issue 25.7)
    assert "landing               none: the vehicle restarted while it flew in OFFBOARD" in out
    assert "landed; AUTO.LOITER disarmed; link ok" in out  # what the view shows after the restart
    after = [line for line in out.split("The vehicle restarted")[1].splitlines() if "fence margin" in line]
    assert after and all(line.endswith("fence margin -") for line in after)  # no old home against the new frame
    assert "Link back" not in out and "will not arm it again on its own" in out
    offboard_s = float(out.split("time in OFFBOARD")[1].split()[0])
    flown_s = float(out.split("OFFBOARD: you have control")[0].rsplit("[", 1)[1].split("]")[0])
    lost_s = float(out.split("Link lost")[0].rsplit("[", 1)[1].split("]")[0])
    assert offboard_s < lost_s - flown_s  # the outage and the time after the restart are not in it


def _read_until(proc: subprocess.Popen[str], text: str, timeout_s: float) -> str:
    """proc's output up to the line holding `text`; fails after timeout_s even if proc prints nothing more (a
    reader thread does the blocking reads, and ends at EOF once the caller killed proc)."""
    stdout = proc.stdout
    assert stdout is not None
    seen: list[str] = []

    def read() -> None:
        for line in iter(stdout.readline, ""):
            seen.append(line)
            if text in line:
                return

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    reader.join(timeout_s)
    if not seen or text not in seen[-1]:
        raise AssertionError(f"never saw {text!r}:\n{''.join(seen)}")
    return "".join(seen)


def test_another_gcs_taking_over_is_reported_and_not_fought(flight: Flight) -> None:
    from pymavlink import mavutil

    _host, port = flight.emulator.node.gcs.link.local_address
    gcs = mavutil.mavlink_connection(f"udpout:127.0.0.1:{port}", source_system=255, source_component=190)
    try:
        gcs.mav.heartbeat_send(6, 8, 0, 0, 4)
        gcs.mav.command_long_send(1, 1, 176, 0, 1 | 128, 4, 3, 0, 0, 0, 0)  # DO_SET_MODE AUTO.LOITER (Hold)
        flight.wait_for(Phase.PAUSED, 3.0)
        assert any("left OFFBOARD for AUTO.LOITER" in n.text for n in flight.session.notes)
        sent = flight.session.setpoints_sent
        flight.wait(4.0)
        assert flight.session.setpoints_sent == sent  # no setpoints, so PX4 has no reason to go back
        assert flight.session.link.state.mode == "AUTO.LOITER"
        flight.button(5, True)  # the script profile's OFFBOARD button
        flight.wait(0.5)
        flight.button(5, False)
        flight.wait_for(Phase.FLYING, 5.0)
        assert flight.session.link.state.offboard
    finally:
        gcs.close()


def test_no_vehicle_exits_with_a_clear_message() -> None:
    port = free_udp_port()
    proc = subprocess.run([sys.executable, "-m", "joyfly", "fly", "--joy", "script:examples/joystick_script.txt",
                           "--url", f"udp://127.0.0.1:{port}@127.0.0.1:{free_udp_port()}", "--connect-timeout", "1"],
                          stdin=subprocess.DEVNULL, capture_output=True, text=True, timeout=30,
                          cwd=REPO_ROOT)
    assert proc.returncode == 1
    assert f"No HEARTBEAT from a vehicle on UDP 127.0.0.1:{port}" in proc.stderr
    assert "sitl-emu serve" in proc.stderr and "Traceback" not in proc.stderr
    assert "distance flown" not in proc.stdout  # nothing flew, so no flight summary
    assert "No HEARTBEAT" not in proc.stdout and proc.stderr.count("No HEARTBEAT") == 1  # said once, on stderr
