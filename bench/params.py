"""Full parameter download from `sitl-emu serve` at real time, timed from outside as a ground station sees it.

A client on the API link (as the probe that recorded PX4 SITL's list: ../shared/reference/px4-params.json, PX4's own
download took 0.981 s) waits for the first HEARTBEAT, sends PARAM_REQUEST_LIST and stops the clock when it holds
_HASH_CHECK and every index 0..param_count-1. The server runs in a fresh temporary working directory (default
parameters). Wall time, best of a few runs.
"""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from pymavlink.dialects.v20 import development as dialect

REPO = Path(__file__).resolve().parent.parent
TIMEOUT_S = 20.0


def _socket() -> socket.socket:
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 22)
    sock.bind(("127.0.0.1", 0))
    sock.settimeout(0.5)
    return sock


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def download_once() -> tuple[float, int]:
    """(wall seconds for the whole list, parameters received) from a fresh `serve`."""
    client, sink = _socket(), _socket()
    api = _free_port()
    args = ["--port", str(api), "--gcs-port", str(_free_port()), "--remote", f"127.0.0.1:{client.getsockname()[1]}",
            "--gcs-remote", f"127.0.0.1:{sink.getsockname()[1]}"]
    with tempfile.TemporaryDirectory() as cwd:
        proc = subprocess.Popen([sys.executable, "-m", "sitl_emu", "serve", "--no-console", *args], cwd=cwd,
                                stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                env={**os.environ, "PYTHONPATH": str(REPO)})
        try:
            return _timed_download(client, ("127.0.0.1", api))
        finally:
            proc.terminate()
            proc.wait(timeout=10)
            client.close()
            sink.close()


def _timed_download(sock: socket.socket, vehicle: tuple[str, int]) -> tuple[float, int]:
    parser = dialect.MAVLink(None)
    mav = dialect.MAVLink(None, srcSystem=255, srcComponent=190)
    deadline = time.monotonic() + TIMEOUT_S
    while not any(m.get_type() == "HEARTBEAT" for m in _receive(sock, parser)):
        if time.monotonic() > deadline:
            raise TimeoutError("no HEARTBEAT from serve")
    start = time.perf_counter()
    sock.sendto(mav.param_request_list_encode(1, 1).pack(mav), vehicle)
    indices: set[int] = set()
    count = -1
    while count < 0 or len(indices) != count + 1:  # every index and _HASH_CHECK's 65535
        if time.monotonic() > deadline:
            raise TimeoutError(f"only {len(indices)} of {count + 1} PARAM_VALUE")
        for msg in _receive(sock, parser):
            if msg.get_type() == "PARAM_VALUE":
                indices.add(msg.param_index)
                count = msg.param_count
    return time.perf_counter() - start, count


def _receive(sock: socket.socket, parser: dialect.MAVLink) -> list:
    try:
        data, _ = sock.recvfrom(65535)
    except TimeoutError:
        return []
    return [m for m in parser.parse_buffer(data) or [] if m.get_type() != "BAD_DATA"]


def download_time(runs: int = 3) -> tuple[float, int]:
    """Best wall time of `runs` downloads, and the parameter count."""
    results = [download_once() for _ in range(runs)]
    return min(r[0] for r in results), results[0][1]


if __name__ == "__main__":
    seconds, params = download_time()
    print(f"parameter download: {seconds:.3f} s wall for {params} parameters + _HASH_CHECK (best of 3)")
