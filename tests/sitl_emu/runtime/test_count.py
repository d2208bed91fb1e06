"""`sitl-emu serve --count N`: N vehicles in one process, numbered and spaced as PX4's multi-vehicle SITL.

Vehicle i answers on API port --port+i and GCS port --gcs-port+i with sysid 1+i (px4-rc.mavlink, reference 1.1/1.3),
starts 3 m east of vehicle i-1, and flying one of them leaves the others where they are.
"""

from __future__ import annotations

import math
import os
import random
import signal
import socket
import subprocess
import sys
from pathlib import Path

import pytest
from support import REPO_ROOT

from px4common.clock import ScaledClock
from sitl_emu.px4 import MavCmd
from sitl_emu.testing.client import FlightClient

REPO = REPO_ROOT
SPEED = 4.0


def _free_run(n: int, exclude: tuple[int, ...] = ()) -> int:
    """A base port such that base..base+n-1 are all free (and clear of `exclude`)."""
    for _ in range(200):
        base = random.randint(20000, 60000)
        socks = []
        try:
            for p in range(base, base + n):
                if any(abs(p - e) < n for e in exclude):
                    raise OSError
                s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
                socks.append(s)
                s.bind(("127.0.0.1", p))
            return base
        except OSError:
            continue
        finally:
            for s in socks:
                s.close()
    raise RuntimeError("no run of free UDP ports")


def _serve_count(cwd: Path, count: int, api: int, gcs: int, sink: int) -> subprocess.Popen:
    args = ["--count", str(count), "--speed", str(SPEED), "--port", str(api), "--gcs-port", str(gcs),
            "--remote", f"127.0.0.1:{sink}", "--gcs-remote", f"127.0.0.1:{sink}"]
    return subprocess.Popen([sys.executable, "-m", "sitl_emu", "serve", "--no-console", *args], cwd=cwd,
                            stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env={**os.environ, "PYTHONPATH": str(REPO)})


def _east_m(a: tuple[float, float], b: tuple[float, float]) -> float:
    return (b[1] - a[1]) * math.radians(1.0) * 6371000.0 * math.cos(math.radians(a[0]))


@pytest.mark.slow
def test_count_3_vehicles_answer_on_their_own_ports_and_flying_one_leaves_the_others(tmp_path):
    api = _free_run(3)
    gcs = _free_run(3, (api,))
    sink = _free_run(3, (api, gcs))
    proc = _serve_count(tmp_path, 3, api, gcs, sink)
    clock = ScaledClock(SPEED)
    clients = [FlightClient(("127.0.0.1", api + i), clock, target_sysid=i + 1) for i in range(3)]
    try:
        assert proc.stdout is not None
        lines = [proc.stdout.readline() for _ in range(3)]
        for i, line in enumerate(lines):
            assert f"sysid {i + 1}:" in line and f":{api + i}," in line and f":{gcs + i}," in line
        assert proc.stdout.readline().startswith("sitl-emu: core: ")  # then which build runs (compiled or pure)
        for c in clients:
            c.wait(lambda c=c: c.healthy and c.seen.lat_lon_deg is not None, 20.0, "a healthy vehicle")
            assert c.seen.heartbeat.get_srcSystem() == c.target[0]
        homes = [c.seen.lat_lon_deg for c in clients]
        assert 2.5 < _east_m(homes[0], homes[1]) < 3.5 and 5.5 < _east_m(homes[0], homes[2]) < 6.5
        flyer = clients[1]
        assert flyer.command(MavCmd.COMPONENT_ARM_DISARM, 1) == 0 and flyer.command(MavCmd.NAV_TAKEOFF) == 0
        flyer.wait(lambda: flyer.seen.pos_ned_m is not None and flyer.seen.pos_ned_m[2] < -2.0, 20.0, "takeoff")
        for c in (clients[0], clients[2]):
            c.spin(0.5)
            assert not c.armed
            assert c.seen.pos_ned_m is not None and math.hypot(*c.seen.pos_ned_m) < 0.05
        assert flyer.armed
    finally:
        for c in clients:
            c.close()
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=10)
    assert proc.returncode == 0 and "Traceback" not in err


def test_a_flood_on_one_vehicle_is_read_in_bounded_slices_while_all_vehicles_keep_stepping_together():
    from pymavlink.dialects.v20 import development as dialect

    from sitl_emu.runtime.swarm import SWARM_IO_BUDGET, SwarmRunner
    from sitl_emu.testing.sim import Sim

    with Sim(count=3) as sim:
        mav = dialect.MAVLink(None, srcSystem=255, srcComponent=190)
        flood = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        flood.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, 1 << 20)
        hb = mav.heartbeat_encode(6, 8, 0, 0, 4).pack(mav)
        for _ in range(3000):
            flood.sendto(hb, sim.ports(0).api)
        flood.close()
        runner = SwarmRunner(sim.nodes, speed=1000.0)
        runner.run(duration_s=0.1)  # 25 ticks of simulated time
        times = [v.time_us for v in sim.vehicles]
        read = sim.nodes[0].api.link.stats.rx_datagrams
    assert times == [100_000] * 3
    assert 0 < read <= 25 * SWARM_IO_BUDGET + SWARM_IO_BUDGET  # the rest waits in vehicle 1's socket buffer


def test_a_vehicle_that_reboots_keeps_its_place_and_the_others_keep_stepping():
    from sitl_emu.runtime.swarm import SwarmRunner
    from sitl_emu.testing.sim import Sim
    from sitl_emu.types import VehicleCommand

    with Sim(count=2) as sim:
        runner = SwarmRunner(sim.nodes, speed=1000.0)
        runner.run(duration_s=0.5)
        reboot = VehicleCommand(MavCmd.PREFLIGHT_REBOOT_SHUTDOWN, (1.0,) + (math.nan,) * 6)  # param1 1: autopilot
        ack = sim.vehicle(0).handle_command(reboot)
        runner.run(duration_s=0.5)
        times = [v.time_us for v in sim.vehicles]
    assert ack is not None and ack.result == 0
    assert runner.timeline_us == 1_000_000
    assert times[1] == 1_000_000
    assert 490_000 <= times[0] <= 500_000  # restarted at 0 half a second ago (the reboot itself takes a tick)
