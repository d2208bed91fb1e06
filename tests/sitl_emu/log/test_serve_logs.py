"""`sitl-emu serve` writes the logs: one file per flight under ./log of its working directory, named by the
"[logger]" text, listed and downloaded over LOG_REQUEST_*; --no-log writes none; an unwritable --log-dir is one
warning and the vehicle still arms and disarms."""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from support import REPO_ROOT
from support.log_flight import RecordingClient
from support.ports import free_udp_ports

from px4common.clock import ScaledClock
from sitl_emu.mavlink.protocols.log import LIST_ALL
from sitl_emu.px4 import MavCmd, MavResult

pytestmark = pytest.mark.slow  # processes or long flights: not in `make test-fast`

pyulog = pytest.importorskip("pyulog", reason="pyulog reads the logs back: pip install pyulog (the test extra)")

SPEED = 5.0
NAN = math.nan


def _serve(cwd: Path, *args: str) -> tuple[subprocess.Popen, RecordingClient]:
    api, gcs, remote = free_udp_ports(3)
    proc = subprocess.Popen([sys.executable, "-m", "sitl_emu", "serve", "--no-console", "--speed", str(SPEED),
                             "--port", str(api), "--gcs-port", str(gcs), "--remote", f"127.0.0.1:{remote}", *args],
                            cwd=cwd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env={**os.environ, "PYTHONPATH": str(REPO_ROOT)})
    client = RecordingClient(("127.0.0.1", api), ScaledClock(SPEED))
    return proc, client


def _stop(proc: subprocess.Popen, client: RecordingClient) -> str:
    client.close()
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=20)
    assert proc.returncode == 0 and "Traceback" not in err, err
    return err


def _texts(c: RecordingClient) -> list[str]:
    return [m.text for m in c.received["STATUSTEXT"]]


def _arm_and_disarm(c: RecordingClient) -> None:
    """Waits are simulated seconds at x5 and generous: a busy CI machine can stall the serve process for a while
    (the client's clock is the wall's; PX4 acks at once otherwise)."""
    c.wait(lambda: c.healthy, 60.0, "health all good")
    assert c.command(MavCmd.COMPONENT_ARM_DISARM, 1, timeout_s=5.0) == MavResult.ACCEPTED
    c.wait(lambda: c.armed, 20.0, "armed")
    c.spin(1.0)
    assert c.command(MavCmd.COMPONENT_ARM_DISARM, 0, timeout_s=5.0) == MavResult.ACCEPTED
    c.wait(lambda: not c.armed, 20.0, "disarmed")


def test_a_flight_writes_exactly_one_log_that_the_log_protocol_serves(tmp_path):
    proc, c = _serve(tmp_path, "--param", "MIS_TAKEOFF_ALT=2")
    try:
        c.wait(lambda: c.healthy, 60.0, "health all good")
        assert c.command(MavCmd.COMPONENT_ARM_DISARM, 1) == MavResult.ACCEPTED
        assert c.command(MavCmd.NAV_TAKEOFF, NAN, NAN, NAN, NAN, NAN, NAN, NAN) == MavResult.ACCEPTED
        c.wait(lambda: c.seen.pos_ned_m is not None and -c.seen.pos_ned_m[2] > 1.8, 30.0, "takeoff altitude")
        assert c.command(MavCmd.NAV_LAND) == MavResult.ACCEPTED
        c.wait(lambda: not c.armed, 40.0, "landing and auto-disarm")
        files = sorted((tmp_path / "log").glob("*/*.ulg"))
        assert len(files) == 1, files
        name = files[0].relative_to(tmp_path).as_posix()
        assert f"[logger] ./{name}\t" in _texts(c)  # PX4 SITL: "[logger] ./log/2026-01-02/03_04_05.ulg"
        c.send(c.mav.log_request_list_encode(1, 1, 0, LIST_ALL))
        c.wait(lambda: bool(c.received["LOG_ENTRY"]), 5.0, "LOG_ENTRY")
        entry = c.received["LOG_ENTRY"][-1]
        assert (entry.num_logs, entry.size) == (1, files[0].stat().st_size)
        c.send(c.mav.log_request_data_encode(1, 1, entry.id, 0, 900))  # the first ten LOG_DATA
        c.wait(lambda: len(c.received["LOG_DATA"]) >= 10, 5.0, "LOG_DATA")
        head = b"".join(bytes(m.data[:m.count]) for m in sorted(c.received["LOG_DATA"], key=lambda m: m.ofs))
        assert head == files[0].read_bytes()[:900]
    finally:
        _stop(proc, c)
    log = pyulog.ULog(str(files[0]))
    assert not log.file_corruption and log.initial_parameters["MIS_TAKEOFF_ALT"] == 2.0
    z = log.get_dataset("vehicle_local_position").data["z"]
    assert -z.min() == pytest.approx(2.0, abs=0.3)
    status = log.get_dataset("vehicle_status").data["arming_state"]
    # SDLOG_MODE 1, PX4 SITL's: the first log runs from boot (disarmed) through the flight to the disarming
    assert status[0] == 1 and 2 in status and status[-1] == 1


def test_no_log_writes_nothing(tmp_path):
    proc, c = _serve(tmp_path, "--no-log")
    try:
        _arm_and_disarm(c)
    finally:
        _stop(proc, c)
    assert not (tmp_path / "log").exists()
    assert not [t for t in _texts(c) if t.startswith("[logger]")]


def test_an_unwritable_log_dir_is_one_warning_and_the_vehicle_flies_on(tmp_path):
    (tmp_path / "taken").write_text("a file, not a directory")
    proc, c = _serve(tmp_path, "--log-dir", "taken/log")
    try:
        _arm_and_disarm(c)
    finally:
        err = _stop(proc, c)
    lines = [line for line in err.splitlines() if "flight log" in line]
    assert len(lines) == 1 and "the flight goes on without a log" in lines[0], err
