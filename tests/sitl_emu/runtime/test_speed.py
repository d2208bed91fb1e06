"""Simulated time at any speed: `sitl-emu serve --speed F` flies the same flight as the in-process lockstep API.

The speed-1 flight would take ~35 s of wall time, so the comparison is in-process lockstep (as fast as the CPU
allows) against `serve --speed 10` in another process, flown by the same scripted pymavlink client (its clock is the
Sim clock in lockstep, wall time x 10 against the server). Both fly with COM_OF_LOSS_T at 10 s: the client is a
Python loop sharing a busy machine, and at x10 PX4's 1 s offboard timeout would be 0.1 s of wall time, so one late
wake-up lost OFFBOARD (at x20, 50 ms did, on CI). With 10 s only a whole second of wall time without a setpoint
loses it; in lockstep no setpoint is ever late, so both flights are the same.

Heartbeats and stream rates are checked per simulated second at --speed 10, waking for every tick, with the default
batching and with --batch-ms 400 (0.4 s of simulated ticks per wake-up).
"""

from __future__ import annotations

import math
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest
from pymavlink.dialects.v20 import development as dialect
from support import REPO_ROOT
from support.ports import free_udp_ports

from px4common.clock import ScaledClock
from sitl_emu.testing.client import FlightClient, fly_square
from sitl_emu.testing.sim import Sim

pytestmark = pytest.mark.slow  # processes or long flights: not in `make test-fast`

REPO = REPO_ROOT




def _serve(cwd: Path, speed: float, api: int, gcs: int, api_remote: int, gcs_remote: int,
           *extra: str) -> subprocess.Popen:
    args = ["--speed", str(speed), "--port", str(api), "--gcs-port", str(gcs), "--remote", f"127.0.0.1:{api_remote}",
            "--gcs-remote", f"127.0.0.1:{gcs_remote}", *extra]
    return subprocess.Popen([sys.executable, "-m", "sitl_emu", "serve", "--no-console", *args], cwd=cwd,
                            stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env={**os.environ, "PYTHONPATH": str(REPO)})


def _stop(proc: subprocess.Popen) -> str:
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=10)
    return err


FAST_SPEED = 10.0
OFFBOARD_LOSS_S = 10.0  # COM_OF_LOSS_T: 1 s of wall time at FAST_SPEED (PX4's default, 1 s, would be 0.1 s)


def test_speed_10_flies_the_same_flight_as_lockstep(tmp_path):
    with Sim(params={"COM_OF_LOSS_T": OFFBOARD_LOSS_S}) as sim:
        client = FlightClient(sim.ports(0).api, sim.clock)
        lockstep = fly_square(client)
        client.close()
    api, gcs, sink = free_udp_ports(3)
    proc = _serve(tmp_path, FAST_SPEED, api, gcs, sink, sink, "--param", f"COM_OF_LOSS_T={OFFBOARD_LOSS_S}",
                  "--no-log")  # about simulated time; logs: tests/sitl_emu/log
    try:
        assert proc.stdout is not None
        proc.stdout.readline()
        client = FlightClient(("127.0.0.1", api), ScaledClock(FAST_SPEED))
        fast = fly_square(client)
        client.close()
    finally:
        err = _stop(proc)
    assert lockstep.ok, lockstep.error
    assert fast.ok, f"{fast.error}\n{err}"
    assert fast.modes == lockstep.modes
    assert lockstep.landing_ned_m is not None and fast.landing_ned_m is not None
    assert math.dist(fast.landing_ned_m, lockstep.landing_ned_m) < 0.25


@pytest.mark.parametrize("batch", [("--batch-ms", "0"), (), ("--batch-ms", "400")],
                         ids=["every-tick", "default-batch", "batch-400ms"])
def test_heartbeat_and_streams_keep_their_rates_in_simulated_time_at_speed_10(batch, tmp_path):
    api, gcs, listen, gcs_sink = free_udp_ports(4)
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 22)
    sock.bind(("127.0.0.1", listen))
    sock.settimeout(5.0)
    # the API link streams to us from boot (initial remote)
    proc = _serve(tmp_path, 10.0, api, gcs, listen, gcs_sink, *batch)
    parser = dialect.MAVLink(None)
    beats, attitude_ms = 0, []
    try:
        data, _ = sock.recvfrom(65535)  # the process has started (its start-up time is not part of the window)
        end = time.monotonic() + 1.5  # ~15 s of simulated time
        while True:
            for msg in parser.parse_buffer(data) or []:
                if msg.get_type() == "HEARTBEAT" and attitude_ms:
                    beats += 1
                elif msg.get_type() == "ATTITUDE":
                    attitude_ms.append(msg.time_boot_ms)
            if time.monotonic() >= end:
                break
            data, _ = sock.recvfrom(65535)
    finally:
        _stop(proc)
        sock.close()
    span_s = (attitude_ms[-1] - attitude_ms[0]) / 1000.0
    assert span_s > 5.0  # simulated time did run faster than the wall clock
    assert abs(beats - span_s) <= 1.5  # HEARTBEAT 1 Hz of simulated time
    assert abs(len(attitude_ms) / span_s - 100.0) < 10.0  # onboard ATTITUDE 100 Hz of simulated time
