"""`sitl-emu serve` as a separate process for conformance tests with real clients (MAVSDK, MAVProxy), and the
MAVSDK loader those tests share."""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any, NamedTuple

import pytest

from support import REPO_ROOT
from support.ports import free_udp_ports


def load_mavsdk() -> Any:
    """mavsdk.asyncio, or skip the test with one sentence when MAVSDK cannot start here."""
    try:
        import mavsdk.asyncio as mavsdk_asyncio
    except Exception as err:  # no package, or its native library cannot be loaded here
        pytest.skip(f"MAVSDK cannot start on this machine: {err}")
    return mavsdk_asyncio


class ServedPorts(NamedTuple):
    api_remote: int  # where the API link sends (MAVSDK listens here)
    gcs_remote: int  # where the ground-station link sends (a ground station listens here)


@contextmanager
def serve(workdir: Path, log_path: Path, speed: float, *extra: str) -> Iterator[ServedPorts]:
    """`sitl-emu serve --speed SPEED` (and `extra` options) on free ports, run in `workdir` (its parameters file and
    FTP root go there); yields the UDP ports its two links send to. The log's tail is printed at the end."""
    client_port, api_port, gcs_port, gcs_remote = free_udp_ports(4)
    args = [sys.executable, "-m", "sitl_emu", "serve", "--no-console", "--speed", str(speed),
            "--port", str(api_port), "--remote", f"127.0.0.1:{client_port}",
            "--gcs-port", str(gcs_port), "--gcs-remote", f"127.0.0.1:{gcs_remote}", *extra]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO_ROOT), os.environ.get("PYTHONPATH", "")])}
    with log_path.open("w") as log_file:
        proc = subprocess.Popen(args, cwd=workdir, env=env, stdout=log_file, stderr=subprocess.STDOUT,
                                stdin=subprocess.DEVNULL)
        try:
            yield ServedPorts(client_port, gcs_remote)
        finally:
            stop_process(proc)
            print("\n--- sitl-emu serve output (tail) ---\n" + log_path.read_text()[-3000:])


def stop_process(proc: subprocess.Popen[Any]) -> None:
    """SIGTERM, then SIGKILL if it is still there after 5 s."""
    proc.terminate()
    try:
        proc.wait(timeout=5)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait(timeout=5)
