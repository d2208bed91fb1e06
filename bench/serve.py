"""`sitl-emu serve` in its own process, measured from outside: start-up, CPU share at real time, fastest flight.

Each measurement starts `python -m sitl_emu serve` on free loopback ports; the API link sends to our scripted client
(sitl_emu.testing.client.FlightClient), the GCS link to a socket nobody reads (the kernel drops what overflows).
CPU is the server process's own user+system time from /proc, so the client's work is not counted.
"""

from __future__ import annotations

import math
import os
import socket
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from px4common.clock import ScaledClock
from sitl_emu.px4 import MavCmd
from sitl_emu.testing.client import FlightClient, FlightResult, fly_square
from sitl_emu.testing.sim import Sim

REPO = Path(__file__).resolve().parent.parent
TICKS_S = os.sysconf("SC_CLK_TCK")


@dataclass
class Server:
    proc: subprocess.Popen
    client: FlightClient
    sink: socket.socket
    started_wall: float
    workdir: tempfile.TemporaryDirectory  # serve's working folder (its parameters file, log/), not the checkout

    def cpu_s(self) -> float:
        """User + system CPU seconds of the server process so far."""
        fields = Path(f"/proc/{self.proc.pid}/stat").read_text().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / TICKS_S

    def stop(self) -> str:
        self.client.close()
        self.proc.terminate()
        try:
            _, err = self.proc.communicate(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            _, err = self.proc.communicate()
        self.sink.close()
        self.workdir.cleanup()
        return err or ""


def _free_port() -> int:
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def start_server(speed: float = 1.0, extra: tuple[str, ...] = ()) -> Server:
    """A server whose API link streams to a fresh FlightClient from boot (PX4's initial remote)."""
    sink = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sink.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    sink.bind(("127.0.0.1", 0))
    api, gcs = _free_port(), _free_port()
    clock = ScaledClock(speed)
    client = FlightClient(("127.0.0.1", api), clock)
    client_port = client.sock.getsockname()[1]
    args = ["--speed", str(speed), "--port", str(api), "--gcs-port", str(gcs),
            "--remote", f"127.0.0.1:{client_port}", "--gcs-remote", f"127.0.0.1:{sink.getsockname()[1]}", *extra]
    workdir = tempfile.TemporaryDirectory(prefix="bench-serve-")
    started = time.monotonic()
    proc = subprocess.Popen([sys.executable, "-m", "sitl_emu", "serve", "--no-console", *args], cwd=workdir.name,
                            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                            env={**os.environ, "PYTHONPATH": str(REPO)})
    return Server(proc, client, sink, started, workdir)


def startup_times() -> tuple[float, float]:
    """Wall seconds from process start to the first HEARTBEAT received, and to health all good."""
    server = start_server()
    try:
        c = server.client
        c.wait(lambda: c.seen.heartbeat is not None, 10.0, "the first HEARTBEAT")
        first = time.monotonic() - server.started_wall
        c.wait(lambda: c.healthy, 20.0, "health all good")
        healthy = time.monotonic() - server.started_wall
    finally:
        server.stop()
    return first, healthy


def hover_cpu_share(seconds: float, extra: tuple[str, ...] = ()) -> float:
    """Percent of one core used by `serve` at real time while hovering in Hold, default streams on both links."""
    return hover_cpu_shares(seconds, extra)[0]


def hover_cpu_shares(seconds: float, extra: tuple[str, ...] = ()) -> tuple[float, float]:
    """As hover_cpu_share: (percent of one core used by `serve` itself, by the processes it started: --view's
    Rerun viewer)."""
    server = start_server(extra=extra)
    try:
        c = server.client
        c.wait(lambda: c.healthy, 20.0, "health all good")
        if c.command(MavCmd.COMPONENT_ARM_DISARM, 1) != 0 or c.command(MavCmd.NAV_TAKEOFF) != 0:
            raise RuntimeError("the vehicle refused to arm or take off")
        c.wait(lambda: c.seen.pos_ned_m is not None and c.seen.pos_ned_m[2] < -2.3, 30.0, "takeoff")
        c.spin(2.0)
        cpu0, children0, wall0 = server.cpu_s(), children_cpu_s(server.proc.pid), time.monotonic()
        c.spin(seconds)
        cpu1, children1, wall1 = server.cpu_s(), children_cpu_s(server.proc.pid), time.monotonic()
        if not c.armed or c.seen.pos_ned_m is None or c.seen.pos_ned_m[2] > -2.0:
            raise RuntimeError("the vehicle did not keep hovering")
    finally:
        server.stop()
    wall = wall1 - wall0
    return 100.0 * (cpu1 - cpu0) / wall, 100.0 * (children1 - children0) / wall


def children_cpu_s(pid: int) -> float:
    """User + system CPU seconds so far of the running direct children of `pid`."""
    total = 0.0
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:  # gone meanwhile
            continue
        if int(fields[1]) == pid:
            total += (int(fields[11]) + int(fields[12])) / TICKS_S
    return total


def lockstep_flight() -> tuple[FlightResult, float]:
    """The reference square flight in-process in lockstep; (result, wall seconds)."""
    with Sim() as sim:
        client = FlightClient(sim.ports(0).api, sim.clock)
        start = time.perf_counter()
        result = fly_square(client)
        wall = time.perf_counter() - start
        client.close()
    return result, wall


def served_flight(speed: float) -> tuple[FlightResult, float, str]:
    """The reference square flight against `serve --speed speed`, timed from the first HEARTBEAT (so the Python
    start-up is not counted); (result, wall seconds, server stderr)."""
    server = start_server(speed)
    try:
        deadline = time.monotonic() + 10.0
        while server.client.seen.heartbeat is None and time.monotonic() < deadline:
            server.client.pump()
            time.sleep(0.002)
        start = time.monotonic()
        result = fly_square(server.client)
        wall = time.monotonic() - start
    finally:
        err = server.stop()
    return result, wall, err


def passes(result: FlightResult, reference: FlightResult) -> bool:
    """Same modes as the lockstep reference and landed within 0.5 m of its landing point."""
    if not result.ok or result.modes != reference.modes or result.landing_ned_m is None:
        return False
    assert reference.landing_ned_m is not None
    return math.dist(result.landing_ned_m, reference.landing_ned_m) < 0.5


KEPT_SPEED = 0.8  # the vehicle's own clock must have run at >= 80 % of the requested speed


def fastest_flight(speeds: list[float], reference: FlightResult) -> list[tuple[float, bool, float, FlightResult]]:
    """Fly at increasing speeds until one fails; every attempt as (speed, passed, wall s, result). An attempt passes
    when the flight passes and the server kept (nearly) the requested speed."""
    attempts = []
    for speed in speeds:
        result, wall, _ = served_flight(speed)
        ok = passes(result, reference) and result.vehicle_duration_s / wall >= KEPT_SPEED * speed
        attempts.append((speed, ok, wall, result))
        if not ok:
            break
    return attempts


def log_size_line(log_dir: Path) -> str:
    """The size per minute of flight of the one ULog in `log_dir` (its duration read with pyulog, if installed)."""
    files = sorted(log_dir.glob("*/*.ulg"))
    if len(files) != 1:
        return f"serve log: expected one .ulg in {log_dir}, found {len(files)}"
    try:
        from pyulog import ULog
    except ImportError:
        return "serve log: install pyulog (the test extra) to measure the log's size per minute"
    log = ULog(str(files[0]))
    minutes = (log.last_timestamp - log.start_timestamp) / 60e6
    size = files[0].stat().st_size
    return (f"serve log: {size / 1e6 / minutes:.2f} MB per minute of flight ({size / 1e6:.2f} MB over "
            f"{minutes * 60:.0f} s)")
