"""`joyfly fly --control position` end to end, as a user runs it: `sitl-emu serve` and `joyfly fly` as processes over
loopback UDP, a FIFO of js_event records as the joystick, and a ground station watching the vehicle on the GCS link
(LOCAL_POSITION_NED at 50 Hz, HEARTBEAT). Both run at --speed 4; the test times its steps on the vehicle's clock
(time_boot_ms), so a slow machine stretches the flight but does not change it. MANUAL_CONTROL goes out at 25 Hz of
vehicle time and PX4 takes it for lost after COM_RC_LOSS_T: 3 s (PX4: 0.5 s, an eighth of a second of wall time at
x4) keeps a busy machine from starving it into an RC-loss failsafe, as in test_fence_e2e.py."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import pytest
from pymavlink import mavutil
from support import REPO_ROOT
from support.fifo import open_writer
from support.ports import free_udp_ports

from joyfly.sticks.js.reader import JS_EVENT_AXIS, JS_EVENT_BUTTON, JS_EVENT_INIT, pack_event

pytestmark = pytest.mark.slow  # processes or long flights: not in `make test-fast`

SPEED = 4.0
RC_LOSS_PARAM = "COM_RC_LOSS_T=3"
AXIS_FULL = 32767
FORWARD, RIGHT, UP, YAW = 0, 1, 2, 3  # the `script` profile's axes
POSCTL = 3


def emulator_flies_posctl() -> bool:
    """Whether sitl_emu takes off by throttle in Position mode (its manual flight tasks, issue 12)."""
    from sitl_emu.types import ManualControlSetpoint, VehicleCommand
    from sitl_emu.vehicle.vehicle import Vehicle

    vehicle = Vehicle()

    def sticks(throttle: float, seconds: float) -> None:
        end = vehicle.time_us + round(seconds * 1e6)
        while vehicle.time_us < end:
            vehicle.manual_control_input(ManualControlSetpoint(throttle=throttle))
            vehicle.run_for(0.04)

    sticks(0.0, 2.0)
    vehicle.handle_command(VehicleCommand(176, (1.0, float(POSCTL), 0.0, 0.0, 0.0, 0.0, 0.0)))
    sticks(0.0, 1.0)
    vehicle.handle_command(VehicleCommand(400, (1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)))
    sticks(1.0, 6.0)
    return vehicle.snapshot().pos_ned_m[2] < -1.0


@dataclass
class GroundStation:
    """Watches the vehicle on its GCS link: positions and heartbeats, stamped with the vehicle's time."""

    port: int
    track: list[tuple[float, tuple[float, float, float]]] = field(default_factory=list)
    armed: bool = False
    custom_mode: int = 0
    _stop: threading.Event = field(default_factory=threading.Event)
    log: Callable[[], str] = lambda: ""  # joyfly's output so far, for failure messages

    def __post_init__(self) -> None:
        self.conn = mavutil.mavlink_connection(f"udpin:127.0.0.1:{self.port}", source_system=245)
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        while not self._stop.is_set():
            msg = self.conn.recv_match(type=["LOCAL_POSITION_NED", "HEARTBEAT"], blocking=True, timeout=0.2)
            if msg is None or msg.get_srcSystem() != 1:
                continue
            if msg.get_type() == "HEARTBEAT":
                self.armed, self.custom_mode = bool(msg.base_mode & 128), msg.custom_mode
            else:
                self.track.append((msg.time_boot_ms / 1000, (msg.x, msg.y, msg.z)))

    @property
    def now(self) -> float:
        return self.track[-1][0] if self.track else 0.0

    def pos(self) -> tuple[float, float, float]:
        return self.track[-1][1]

    def since(self, t_s: float) -> list[tuple[float, float, float]]:
        return [p for t, p in list(self.track) if t >= t_s]

    def wait_for(self, what: str, done: Callable[[], bool], sim_s: float) -> None:
        give_up = time.monotonic() + sim_s / SPEED * 3 + 5
        while not done():
            assert time.monotonic() < give_up, f"never saw: {what}\n{self.log()}"
            time.sleep(0.02)

    def wait(self, sim_s: float) -> None:
        end = self.now + sim_s
        self.wait_for(f"{sim_s} s of vehicle time", lambda: self.now >= end, sim_s)

    def close(self) -> None:
        self._stop.set()
        self.thread.join(2.0)
        self.conn.close()


@dataclass
class Pair:
    emu: subprocess.Popen[bytes]
    joy: subprocess.Popen[str]
    gcs: GroundStation
    fifo_fd: int
    out: list[str]

    def stick(self, axis: int, value: float) -> None:
        os.write(self.fifo_fd, pack_event(JS_EVENT_AXIS, axis, round(value * AXIS_FULL)))


def _start(tmp_path: Path) -> Pair:
    fifo = tmp_path / "js0"
    os.mkfifo(fifo)
    joy_port, emu_port, gcs_port, gcs_remote = free_udp_ports(4)
    gcs = GroundStation(gcs_remote)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO_ROOT), os.environ.get("PYTHONPATH", "")])}
    emu = subprocess.Popen([sys.executable, "-m", "sitl_emu", "serve", "--no-console", "--speed", str(SPEED),
                            "--param", RC_LOSS_PARAM, "--port", str(emu_port), "--remote", f"127.0.0.1:{joy_port}",
                            "--gcs-port", str(gcs_port), "--gcs-remote", f"127.0.0.1:{gcs_remote}"], cwd=tmp_path,
                           env=env,
                           stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    joy = subprocess.Popen([sys.executable, "-m", "joyfly", "fly", "--control", "position", "--joy", str(fifo),
                            "--profile", "script", "--fence", "5", "--speed", str(SPEED),
                            "--url", f"udp://127.0.0.1:{joy_port}@127.0.0.1:{emu_port}"], cwd=tmp_path, env=env,
                           stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    out: list[str] = []
    threading.Thread(target=lambda: out.extend(iter(joy.stdout.readline, "")), daemon=True).start()  # type: ignore[union-attr]
    gcs.log = lambda: "".join(out)
    fd = open_writer(fifo, 20.0)
    for index in range(7):
        os.write(fd, pack_event(JS_EVENT_BUTTON | JS_EVENT_INIT, index, 0))
    for index in range(4):
        os.write(fd, pack_event(JS_EVENT_AXIS | JS_EVENT_INIT, index, 0))
    return Pair(emu, joy, gcs, fd, out)


@pytest.fixture
def pair(tmp_path: Path) -> Iterator[Pair]:
    if not emulator_flies_posctl():
        pytest.skip("sitl_emu does not fly Position mode from MANUAL_CONTROL yet (issue 12: the emulator's POSCTL "
                    "flight task, takeoff by throttle)")
    p = _start(tmp_path)
    try:
        yield p
    finally:
        for proc in (p.joy, p.emu):
            if proc.poll() is None:
                proc.kill()
                proc.wait()
        os.close(p.fifo_fd)
        p.gcs.close()


def test_position_mode_with_a_fifo_joystick_from_arming_to_ctrl_c(pair: Pair) -> None:
    gcs, log = pair.gcs, lambda: "".join(pair.out)
    gcs.wait_for("armed in POSCTL", lambda: gcs.armed and (gcs.custom_mode >> 16) & 0xFF == POSCTL, 30.0)
    pair.stick(UP, 1.0)  # the throttle takes off (PX4's spool-up and takeoff ramp first)
    gcs.wait_for("above 2 m", lambda: bool(gcs.track) and -gcs.pos()[2] > 2.5, 20.0)
    pair.stick(UP, 0.0)
    gcs.wait(3.0)
    held, start = gcs.pos(), gcs.now
    gcs.wait(5.0)
    assert max(max(abs(a - b) for a, b in zip(p, held, strict=True)) for p in gcs.since(start)) < 0.5, log()
    pair.stick(FORWARD, 0.5)
    gcs.wait(2.0)
    pair.stick(FORWARD, 0.0)
    gcs.wait(4.0)
    x, y, _ = gcs.pos()
    assert x > held[0] + 1.0 and abs(y - held[1]) < 0.5  # forward flies north (the nose points north)
    start = gcs.now
    pair.stick(RIGHT, 1.0)
    gcs.wait(15.0)
    assert max(abs(p[1]) for p in gcs.since(start)) < 5.0 and gcs.pos()[1] > 4.0  # stops at the fence
    pair.stick(RIGHT, 0.0)
    assert max(max(abs(p[0]), abs(p[1])) for p in gcs.since(0.0)) < 5.0
    pair.joy.send_signal(signal.SIGINT)
    assert pair.joy.wait(60.0) == 0, log()
    time.sleep(0.2)
    text = log()
    assert "Exiting: land" in text and "Landed and disarmed" in text and "Traceback" not in text, text
    assert "time in POSCTL" in text and re.search(r"vehicle at the end    \S+, disarmed", text), text
    assert not gcs.armed
