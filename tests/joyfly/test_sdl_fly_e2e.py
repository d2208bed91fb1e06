"""`joyfly fly --joy sdl` end to end with an SDL virtual game controller, against a real vehicle over UDP (sitl_emu's
node in this process, on free loopback ports): arms, takes off, flies north then east from the sticks, lands; the
controller unplugged mid-flight holds, plugged back in (same GUID) flies on; another controller plugged in meanwhile
is never taken, and the vehicle lands after --joy-timeout.

A virtual SDL device exists only in the process that attached it, so joyfly runs inside tests/support/sdl_pilot.py,
which moves the virtual sticks as this test tells it on its stdin.
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

import pytest
from support import REPO_ROOT
from support.calibration_user import CalibrationUser
from support.ports import free_udp_port
from support.sdl_virtual import RIGHT_X, RIGHT_Y, A, VirtualPad

from joyfly.demo import EmbeddedVehicle, VehicleTimeClock
from joyfly.sticks.profiles.calibrate import Wizard
from joyfly.sticks.profiles.user import profile_toml, write_user_profile
from joyfly.sticks.sources import open_source
from px4common.clock import WallClock

# the wizard's user: throttle on axis 3, yaw 0, pitch 2 (forward negative), roll 1 (right negative)
GAMEPADISH = {"up": (3, -1.0, 0.0), "yaw": (0, 1.0, 0.0), "forward": (2, -1.0, 0.0), "right": (1, -1.0, 0.0)}

SPEED = 4.0
PILOT = REPO_ROOT / "tests" / "support" / "sdl_pilot.py"


@dataclass
class Flight:
    emulator: EmbeddedVehicle
    clock: VehicleTimeClock
    proc: subprocess.Popen[str]
    out: list[str] = field(default_factory=list)
    err: list[str] = field(default_factory=list)

    def text(self) -> str:
        return "".join(self.out) + "".join(self.err)

    def send(self, command: str) -> None:
        assert self.proc.stdin is not None
        done = len([ln for ln in self.err if ln.startswith(f"pilot: done {command}")])
        self.proc.stdin.write(command + "\n")
        self.proc.stdin.flush()
        self.until(lambda: len([ln for ln in self.err if ln.startswith(f"pilot: done {command}")]) > done, 10.0,
                   f"the pilot to do {command}")

    def until(self, cond: object, sim_s: float, what: str) -> None:
        end = self.clock.now() + sim_s
        wall_end = time.monotonic() + sim_s / SPEED * 4 + 30.0
        while not cond() and self.clock.now() < end and time.monotonic() < wall_end:  # type: ignore[operator]
            assert self.proc.poll() is None or cond(), f"joyfly exited waiting for {what}:\n{self.text()}"  # type: ignore[operator]
            time.sleep(0.02)
        assert cond(), f"no {what} after {sim_s} s:\n{self.text()}"  # type: ignore[operator]

    def said(self, fragment: str) -> bool:
        return fragment in self.text()

    def pos(self) -> tuple[float, float, float]:
        return tuple(self.emulator.node.vehicle.snapshot().pos_ned_m)  # type: ignore[return-value]

    @property
    def armed(self) -> bool:
        return bool(self.emulator.node.vehicle.snapshot().armed)

    def wait(self, sim_s: float) -> None:
        end = self.clock.now() + sim_s
        self.until(lambda: self.clock.now() >= end, sim_s + 1.0, f"{sim_s} s to pass")


def _reader(stream: object, into: list[str]) -> None:
    for line in stream:  # type: ignore[attr-defined]
        into.append(line)


@dataclass
class Vehicle:
    emulator: EmbeddedVehicle
    joy_port: int  # where the vehicle sends to: joyfly's port


@pytest.fixture
def vehicle() -> Iterator[Vehicle]:
    joy_port = free_udp_port()
    emulator = EmbeddedVehicle(joy_port, SPEED)
    emulator.start()
    try:
        yield Vehicle(emulator, joy_port)
    finally:
        emulator.stop()


def start(vehicle: Vehicle, pilot_args: list[str], joy: str, *fly_args: str,
          env: dict[str, str] | None = None) -> Flight:
    """tests/support/sdl_pilot.py running `joyfly fly --joy joy` against the vehicle."""
    emulator = vehicle.emulator
    host, port = emulator.api_address
    url = f"udp://127.0.0.1:{vehicle.joy_port}@{host}:{port}"
    proc = subprocess.Popen(
        [sys.executable, str(PILOT), *pilot_args, "--", "fly", "--joy", joy, "--url", url, "--speed", str(SPEED),
         "--joy-timeout", "3", "--connect-timeout", "60", *fly_args],
        cwd=REPO_ROOT, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        env={**os.environ, **(env or {})})
    f = Flight(emulator, emulator.clock(), proc)
    for stream, into in ((proc.stdout, f.out), (proc.stderr, f.err)):
        threading.Thread(target=_reader, args=(stream, into), daemon=True).start()
    return f


def stop(f: Flight) -> None:
    if f.proc.poll() is None:
        f.proc.send_signal(signal.SIGINT)
    try:
        f.proc.wait(30.0)
    except subprocess.TimeoutExpired:
        f.proc.kill()


def take_off(f: Flight) -> None:
    f.until(lambda: f.said("OFFBOARD: you have control"), 60.0, "OFFBOARD")
    f.until(lambda: -f.pos()[2] > 2.5, 30.0, "the climb")


@pytest.fixture
def flight(vehicle: Vehicle) -> Iterator[Flight]:
    f = start(vehicle, [], "sdl")
    try:
        take_off(f)
        yield f
    finally:
        stop(f)


@pytest.mark.slow
def test_joy_sdl_arms_takes_off_flies_north_then_east_and_lands(flight: Flight) -> None:
    assert flight.said("--joy sdl chose sdl:0 \"Pilot Pad\" (game controller")
    assert flight.said("profile sdl-gamecontroller")
    n0, e0, _ = flight.pos()
    flight.send(f"axis {RIGHT_Y} -0.5")  # right stick forward: north
    flight.until(lambda: flight.pos()[0] - n0 > 2.0, 15.0, "2 m north")
    flight.send(f"axis {RIGHT_Y} 0")
    flight.wait(2.0)
    n1, e1, _ = flight.pos()
    assert n1 - n0 > 2.0 and abs(e1 - e0) < 0.5
    flight.send(f"axis {RIGHT_X} 0.5")  # right stick right: east
    flight.until(lambda: flight.pos()[1] - e1 > 2.0, 15.0, "2 m east")
    flight.send(f"axis {RIGHT_X} 0")
    flight.wait(2.0)
    n2, e2, _ = flight.pos()
    assert e2 - e1 > 2.0 and abs(n2 - n1) < 0.5
    flight.send(f"button {A} 1")  # A: land
    flight.wait(0.5)
    flight.send(f"button {A} 0")
    flight.until(lambda: flight.said("Landed and disarmed"), 40.0, "the landing")
    assert flight.said("LAND pressed: landing") and not flight.armed


@pytest.mark.slow
def test_unplugged_holds_plugged_back_flies_on_another_pad_is_never_taken(flight: Flight) -> None:
    flight.send("detach")
    flight.until(lambda: flight.said("Joystick lost: holding position"), 5.0, "the hold")
    held = flight.pos()
    flight.wait(1.0)
    assert abs(flight.pos()[0] - held[0]) < 0.5 and flight.armed
    flight.send("attach")
    flight.until(lambda: flight.said("Joystick back"), 5.0, "the joystick back")
    n0 = flight.pos()[0]
    flight.send(f"axis {RIGHT_Y} -0.5")
    flight.until(lambda: flight.pos()[0] - n0 > 1.5, 15.0, "the sticks flying again")
    flight.send(f"axis {RIGHT_Y} 0")
    flight.wait(1.0)
    backs = flight.text().count("Joystick back")
    flight.send("detach")
    flight.send("other")  # another controller: joyfly must not fly with it
    flight.until(lambda: flight.said("Joystick still lost after 3 s: landing"), 8.0, "the landing after --joy-timeout")
    assert flight.text().count("Joystick back") == backs
    assert flight.said("Ignoring \"Somebody Else's Pad\"")  # said, not silent
    flight.until(lambda: not flight.armed, 40.0, "the vehicle to land and disarm")


def refused(f: Flight) -> str:
    """joyfly's one sentence, after checking it exited 2 without arming or sending the vehicle anything."""
    assert f.proc.wait(60.0) == 2, f.text()
    time.sleep(0.1)
    lines = [ln for ln in f.err if not ln.startswith("pilot: ")]
    assert len(lines) == 1 and lines[0].startswith("joyfly: ") and lines[0].rstrip().endswith("."), f.text()
    assert not f.armed and int(f.emulator.node.api.link.stats.rx_datagrams) == 0
    return lines[0]


def test_joy_sdl_with_no_controller_names_the_list_command_and_arms_nothing(vehicle: Vehicle) -> None:
    line = refused(start(vehicle, ["--none"], "sdl"))
    assert "No game controller is connected" in line and "`joyfly joystick list`" in line


def test_joy_sdl_7_with_two_controllers_lists_them(vehicle: Vehicle) -> None:
    line = refused(start(vehicle, ["--also", "Second Pad"], "sdl:7"))
    assert "There is no SDL device 7" in line and "sdl:0 \"Pilot Pad\"" in line and "sdl:1 \"Second Pad\"" in line


def test_an_unknown_plain_joystick_is_refused_before_arming(vehicle: Vehicle) -> None:
    line = refused(start(vehicle, ["--joystick", "Mystery Stick 3000"], "auto"))
    assert "\"Mystery Stick 3000\"" in line and "not know as a game controller" in line


@pytest.mark.slow
def test_a_plain_joystick_with_a_profile_flies(vehicle: Vehicle) -> None:
    f = start(vehicle, ["--joystick", "Mystery Stick 3000"], "sdl:mystery", "--profile", "generic")
    try:
        take_off(f)
        n0 = f.pos()[0]
        f.send("axis 1 -0.5")  # the generic profile: axis 1 pushed up (negative) flies north
        f.until(lambda: f.pos()[0] - n0 > 1.5, 15.0, "1.5 m north")
    finally:
        stop(f)


FENCE_PULSE = f"pilot: rumble {round(0.3 * 65535)} {round(0.7 * 65535)}"  # joyfly.rumble.PULSES["fence"]


def push_into_the_fence(f: Flight) -> None:
    f.send(f"axis {RIGHT_Y} -1.0")  # full forward, towards the 5 m fence north of home
    f.until(lambda: f.pos()[0] > 4.5, 20.0, "the fence")
    f.wait(1.0)
    f.send("rumbles")


@pytest.mark.slow
def test_a_fence_push_rumbles_the_pad(flight: Flight) -> None:
    push_into_the_fence(flight)
    assert flight.said(FENCE_PULSE)


@pytest.mark.slow
def test_no_rumble_keeps_the_pad_still(vehicle: Vehicle) -> None:
    f = start(vehicle, [], "sdl", "--no-rumble")
    try:
        take_off(f)
        push_into_the_fence(f)
        assert not f.said("pilot: rumble ")
    finally:
        stop(f)


@pytest.mark.slow
def test_a_joystick_calibrated_by_the_wizard_then_flies(vehicle: Vehicle, tmp_path: Path) -> None:
    """The wizard, driven by a virtual joystick here, writes the profile; joyfly (in the pilot's process, where a
    virtual joystick with the same name and GUID is plugged in) flies it with that profile."""
    pad = VirtualPad.joystick("Calibrated Stick")  # what the pilot plugs in: the same GUID
    try:
        source = open_source(f"sdl:{pad.index}", WallClock()).source
        profile = Wizard(source, CalibrationUser(pad, GAMEPADISH, {"land": 0})).run()
        guid = str(getattr(source, "guid", ""))
        write_user_profile(profile_toml(source.name, guid, profile), source.name, tmp_path)
        source.close()
    finally:
        pad.detach()
    f = start(vehicle, ["--joystick", "Calibrated Stick"], "auto", env={"JOYFLY_PROFILES": str(tmp_path)})
    try:
        take_off(f)
        assert f.said("profile calibrated:calibrated-stick")
        n0 = f.pos()[0]
        f.send("axis 2 -0.5")  # the axis calibrated as pitch, pushed forward
        f.until(lambda: f.pos()[0] - n0 > 1.5, 15.0, "1.5 m north")
    finally:
        stop(f)
