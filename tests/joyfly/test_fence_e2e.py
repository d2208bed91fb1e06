"""The fence end to end (issue 25.2): `sitl-emu serve` in a wind stronger than the vehicle can fight and `joyfly fly`,
both as subprocesses over loopback UDP, as a user runs them. The wind carries the vehicle out of joyfly's fence;
joyfly must say so at once, carry out --fence-action once it stays outside, and exit non-zero.

A ground station listening on the emulator's GCS link (pymavlink) sees what the vehicle did, independently of
joyfly: where it went and which mode it flew in.
"""

from __future__ import annotations

import os
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import pytest
from pymavlink import mavutil
from support import REPO_ROOT
from support.fifo import open_writer
from support.ports import free_udp_ports

from joyfly.sticks.js.reader import JS_EVENT_AXIS, JS_EVENT_BUTTON, JS_EVENT_INIT, pack_event

pytestmark = pytest.mark.slow  # processes or long flights: not in `make test-fast`

SPEED = 8
# MANUAL_CONTROL goes out at 25 Hz of vehicle time and PX4 takes it for lost after COM_RC_LOSS_T: x4 and 3 s (PX4:
# 0.5 s) keep a busy machine from starving it into an RC-loss failsafe (a failsafe, not joyfly, would then be in
# charge, and rightly joyfly would not act)
MANUAL_SPEED = 4
MANUAL_PARAMS = ["--param", "COM_RC_LOSS_T=3"]
WIND = "11@270"  # from the west: 11 m/s needs 48 deg of tilt against SIH's drag, more than MPC_TILTMAX_AIR's 45
AUTO, LAND_SUB, LOITER_SUB, POSCTL = 4, 6, 3, 3
UP_AXIS = 2  # the script profile's axes: forward, right, up, yaw


@dataclass
class GroundStation:
    """Listens on the vehicle's GCS link: its modes (main, sub) with the farthest east it had been by then."""

    port: int
    modes: list[tuple[int, int, bool, float]] = field(default_factory=list)  # main, sub, armed, max east so far
    max_east_m: float = 0.0
    alt_m: float = 0.0
    _stop: threading.Event = field(default_factory=threading.Event)

    def __post_init__(self) -> None:
        self.conn = mavutil.mavlink_connection(f"udpin:127.0.0.1:{self.port}", source_system=245)
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        while not self._stop.is_set():
            msg = self.conn.recv_match(type=["LOCAL_POSITION_NED", "HEARTBEAT"], blocking=True, timeout=0.2)
            if msg is None or msg.get_srcSystem() != 1:
                continue
            if msg.get_type() == "LOCAL_POSITION_NED":
                self.max_east_m, self.alt_m = max(self.max_east_m, msg.y), -msg.z
                continue
            mode = ((msg.custom_mode >> 16) & 0xFF, (msg.custom_mode >> 24) & 0xFF, bool(msg.base_mode & 128),
                    self.max_east_m)
            if not self.modes or self.modes[-1][:3] != mode[:3]:
                self.modes.append(mode)

    def wait_for(self, what: str, done: Callable[[], bool], wall_s: float, log: Callable[[], str]) -> None:
        give_up = time.monotonic() + wall_s
        while not done():
            assert time.monotonic() < give_up, f"never saw: {what}; modes {self.modes}\n{log()}"
            time.sleep(0.02)

    def close(self) -> None:
        self._stop.set()
        self.thread.join(2.0)
        self.conn.close()


def _env() -> dict[str, str]:
    return {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO_ROOT), os.environ.get("PYTHONPATH", "")])}


def _serve(tmp_path: Path, ports: list[int], speed: int = SPEED,
           extra: tuple[str, ...] = ()) -> subprocess.Popen[bytes]:
    joy_port, emu_port, gcs_port, gcs_remote = ports
    return subprocess.Popen([sys.executable, "-m", "sitl_emu", "serve", "--no-console", "--speed", str(speed), *extra,
                             "--wind", WIND, "--port", str(emu_port), "--remote", f"127.0.0.1:{joy_port}",
                             "--gcs-port", str(gcs_port), "--gcs-remote", f"127.0.0.1:{gcs_remote}"],
                            cwd=tmp_path, env=_env(), stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)


def _assert_warned_then_landed(out: str) -> None:
    """A WARNING the moment the vehicle is outside, the landing 5 s later (it is carried away, never coming back)."""
    warned = out.index("WARNING The vehicle is ")
    assert "m outside the fence (5 m around home)" in out[warned:].splitlines()[0]
    acted = out.index("WARNING The vehicle has been outside the fence for ")
    assert "landing where it is (--fence-action land)" in out[acted:].splitlines()[0]
    t_warned, t_acted = (float(out[:i].rsplit("[", 1)[1].split("]")[0]) for i in (warned, acted))
    assert 4.9 <= t_acted - t_warned <= 7.0  # 5 s; later when a busy machine delays the vehicle's telemetry


def test_wind_carries_the_vehicle_out_of_the_fence_joyfly_warns_lands_it_and_exits_3(tmp_path: Path) -> None:
    ports = free_udp_ports(4)
    joy_port, emu_port, _, gcs_remote = ports
    gcs = GroundStation(gcs_remote)
    env = _env()
    script = tmp_path / "hover.txt"
    script.write_text("0 forward=0\n+40 end\n")  # centred sticks: joyfly's setpoint stays over home
    emu = _serve(tmp_path, ports)
    try:
        joy = subprocess.run([sys.executable, "-m", "joyfly", "fly", "--joy", f"script:{script}", "--fence", "5",
                              "--speed", str(SPEED), "--url", f"udp://127.0.0.1:{joy_port}@127.0.0.1:{emu_port}"],
                             cwd=tmp_path, env=env, stdin=subprocess.DEVNULL, capture_output=True, text=True,
                             timeout=90)
        time.sleep(0.3)
    finally:
        emu.kill()
        emu.wait()
        gcs.close()
    out = joy.stdout
    assert joy.returncode == 3, out + joy.stderr
    _assert_warned_then_landed(out)
    assert "Landed and disarmed" in out and "fence breached        once" in out
    assert "went outside the 5 m fence" in joy.stderr and "Traceback" not in joy.stderr
    # on the wire: OFFBOARD, blown east beyond the fence, then AUTO.LAND (joyfly's NAV_LAND), then disarmed
    offboard = next(i for i, m in enumerate(gcs.modes) if m[0] == 6 and m[2])
    land = next(i for i, m in enumerate(gcs.modes) if m[:2] == (AUTO, LAND_SUB))
    assert offboard < land and gcs.modes[land][2] and gcs.modes[land][3] > 5.5, gcs.modes
    assert not gcs.modes[-1][2], gcs.modes


def test_in_position_mode_too_the_wind_carried_vehicle_is_warned_landed_and_exits_3(tmp_path: Path) -> None:
    ports = free_udp_ports(4)
    joy_port, emu_port, _, gcs_remote = ports
    gcs = GroundStation(gcs_remote)
    fifo = tmp_path / "js0"
    os.mkfifo(fifo)
    emu = _serve(tmp_path, ports, MANUAL_SPEED, tuple(MANUAL_PARAMS))
    joy = subprocess.Popen([sys.executable, "-m", "joyfly", "fly", "--control", "position", "--joy", str(fifo),
                            "--profile", "script", "--fence", "5", "--speed", str(MANUAL_SPEED),
                            "--url", f"udp://127.0.0.1:{joy_port}@127.0.0.1:{emu_port}"], cwd=tmp_path, env=_env(),
                           stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    out: list[str] = []
    threading.Thread(target=lambda: out.extend(iter(joy.stdout.readline, "")), daemon=True).start()  # type: ignore[union-attr]
    log = lambda: "".join(out)  # noqa: E731
    fd = -1
    try:
        fd = open_writer(fifo, 20.0)
        for index in range(7):
            os.write(fd, pack_event(JS_EVENT_BUTTON | JS_EVENT_INIT, index, 0))
        for index in range(4):
            os.write(fd, pack_event(JS_EVENT_AXIS | JS_EVENT_INIT, index, 0))
        gcs.wait_for("armed in POSCTL", lambda: bool(gcs.modes) and gcs.modes[-1][0] == POSCTL and gcs.modes[-1][2],
                     30.0, log)
        # joyfly knows it too (its throttle interlock opened with the stick centred after the ARM), then the throttle
        gcs.wait_for("joyfly's 'Armed in Position mode'", lambda: "push the throttle up" in log(), 10.0, log)
        os.write(fd, pack_event(JS_EVENT_AXIS, UP_AXIS, 32767))
        gcs.wait_for("2 m up", lambda: gcs.alt_m > 2.0, 20.0, log)
        os.write(fd, pack_event(JS_EVENT_AXIS, UP_AXIS, 0))
        gcs.wait_for("AUTO.LAND, then disarmed", lambda: any(m[:2] == (AUTO, LAND_SUB) for m in gcs.modes)
                     and not gcs.modes[-1][2], 40.0, log)
        os.close(fd)  # the joystick goes away: landed and disarmed, joyfly is done
        fd = -1
        joy.wait(30.0)
        time.sleep(0.2)
        stderr = joy.stderr.read() if joy.stderr else ""
    finally:
        for proc in (joy, emu):
            if proc.poll() is None:
                proc.kill()
                proc.wait()
        if fd >= 0:
            os.close(fd)
        gcs.close()
    text = log()
    assert joy.returncode == 3, text + stderr
    _assert_warned_then_landed(text)
    land = next(m for m in gcs.modes if m[:2] == (AUTO, LAND_SUB))
    assert land[3] > 5.5, gcs.modes  # it was beyond the fence before the landing began
    assert "fence breached        once" in text and "time in POSCTL" in text and "Traceback" not in stderr
    assert text.count("m outside the fence (5 m around home)") == 1  # said once, however long it lasts
