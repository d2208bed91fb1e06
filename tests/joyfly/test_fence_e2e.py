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
from dataclasses import dataclass, field
from pathlib import Path

from pymavlink import mavutil
from support import REPO_ROOT
from support.ports import free_udp_ports

SPEED = 8
WIND = "11@270"  # from the west: 11 m/s needs 48 deg of tilt against SIH's drag, more than MPC_TILTMAX_AIR's 45
AUTO, LAND_SUB, LOITER_SUB = 4, 6, 3


@dataclass
class GroundStation:
    """Listens on the vehicle's GCS link: its modes (main, sub) with the farthest east it had been by then."""

    port: int
    modes: list[tuple[int, int, bool, float]] = field(default_factory=list)  # main, sub, armed, max east so far
    max_east_m: float = 0.0
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
                self.max_east_m = max(self.max_east_m, msg.y)
                continue
            mode = ((msg.custom_mode >> 16) & 0xFF, (msg.custom_mode >> 24) & 0xFF, bool(msg.base_mode & 128),
                    self.max_east_m)
            if not self.modes or self.modes[-1][:3] != mode[:3]:
                self.modes.append(mode)

    def close(self) -> None:
        self._stop.set()
        self.thread.join(2.0)
        self.conn.close()


def test_wind_carries_the_vehicle_out_of_the_fence_joyfly_warns_lands_it_and_exits_3(tmp_path: Path) -> None:
    joy_port, emu_port, gcs_port, gcs_remote = free_udp_ports(4)
    gcs = GroundStation(gcs_remote)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO_ROOT), os.environ.get("PYTHONPATH", "")])}
    script = tmp_path / "hover.txt"
    script.write_text("0 forward=0\n+40 end\n")  # centred sticks: joyfly's setpoint stays over home
    emu = subprocess.Popen([sys.executable, "-m", "sitl_emu", "serve", "--no-console", "--speed", str(SPEED),
                            "--wind", WIND, "--port", str(emu_port), "--remote", f"127.0.0.1:{joy_port}",
                            "--gcs-port", str(gcs_port), "--gcs-remote", f"127.0.0.1:{gcs_remote}"],
                           cwd=tmp_path, env=env, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL)
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
    warned = out.index("WARNING The vehicle is ")
    assert "m outside the fence (5 m around home)" in out[warned:].splitlines()[0]
    acted = out.index("WARNING The vehicle has been outside the fence for ")
    assert "landing where it is (--fence-action land)" in out[acted:].splitlines()[0]
    t_warned, t_acted = (float(out[:i].rsplit("[", 1)[1].split("]")[0]) for i in (warned, acted))
    assert 4.9 <= t_acted - t_warned <= 5.5
    assert "Landed and disarmed" in out and "fence breached        once" in out
    assert "went outside the 5 m fence" in joy.stderr and "Traceback" not in joy.stderr
    # on the wire: OFFBOARD, blown east beyond the fence, then AUTO.LAND (joyfly's NAV_LAND), then disarmed
    offboard = next(i for i, m in enumerate(gcs.modes) if m[0] == 6 and m[2])
    land = next(i for i, m in enumerate(gcs.modes) if m[:2] == (AUTO, LAND_SUB))
    assert offboard < land and gcs.modes[land][2] and gcs.modes[land][3] > 5.5, gcs.modes
    assert not gcs.modes[-1][2], gcs.modes
