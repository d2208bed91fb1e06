"""`sitl-emu serve --signing-key FILE` starts signed, stores the key as PX4 stores a SETUP_SIGNING key, and a later
start without the option signs with the stored key; a file that holds no key is one sentence and status 2."""

from __future__ import annotations

import hashlib
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

from px4common.signing_key import timestamp_from_unix_us
from sitl_emu.mavlink.wire.signing import signature_matches
from sitl_emu.px4 import MavCmd

pytestmark = pytest.mark.slow  # processes or long flights: not in `make test-fast`

KEY = hashlib.sha256(b"serve signing test").digest()


def _serve(cwd: Path, *args: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "sitl_emu", "serve", "--no-console", "--speed", "4", *args],
                            cwd=cwd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env={**os.environ, "PYTHONPATH": str(REPO_ROOT)})


class _Client:
    def __init__(self, port: int, target: int, key: bytes | None) -> None:
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(("127.0.0.1", port))
        self.sock.settimeout(0.2)
        self.target = ("127.0.0.1", target)
        self.mav = dialect.MAVLink(None, srcSystem=255, srcComponent=190)
        if key is not None:
            self.mav.signing.secret_key, self.mav.signing.sign_outgoing = key, True
            self.mav.signing.timestamp = timestamp_from_unix_us(time.time_ns() // 1000)
        self.parser = dialect.MAVLink(None)

    def send(self, msg: object) -> None:
        self.sock.sendto(msg.pack(self.mav), self.target)

    def heartbeats_until(self, seconds: float, want: str) -> list[object]:
        """Send a heartbeat every 0.2 s and collect what comes back until a `want` message (or time is up)."""
        got: list[object] = []
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline and not any(m.get_type() == want for m in got):
            self.send(self.mav.heartbeat_encode(6, 8, 0, 0, 0, 3))
            try:
                data = self.sock.recv(65535)
            except TimeoutError:
                continue
            got += [m for m in self.parser.parse_buffer(data) or [] if m.get_type() != "BAD_DATA"]
        return got


def _arm_answered(workdir: Path, key_args: tuple[str, ...], client_key: bytes | None) -> tuple[bool, list[bytes]]:
    """Start serve in `workdir`, wait until it can arm, send ARM: (whether an ACK came back, the frames received)."""
    client_port, api_port, gcs_port, gcs_remote = free_udp_ports(4)
    proc = _serve(workdir, "--port", str(api_port), "--remote", f"127.0.0.1:{client_port}",
                  "--gcs-port", str(gcs_port), "--gcs-remote", f"127.0.0.1:{gcs_remote}", *key_args)
    client = _Client(client_port, api_port, client_key)
    try:
        got = client.heartbeats_until(30.0, "SYS_STATUS")  # serve is up (its start-up is slow on a busy machine)
        time.sleep(1.0)  # the estimator's warm-up: 2.5 simulated s
        deadline = time.monotonic() + 8.0  # ARM again each second until an ACK (or time is up: unanswered)
        while time.monotonic() < deadline and not any(m.get_type() == "COMMAND_ACK" for m in got):
            client.send(client.mav.command_long_encode(1, 1, MavCmd.COMPONENT_ARM_DISARM, 0, 1, 0, 0, 0, 0, 0, 0))
            got += client.heartbeats_until(1.0, "COMMAND_ACK")
    finally:
        client.sock.close()
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=10)
    assert proc.returncode == 0 and "Traceback" not in err, err
    return any(m.get_type() == "COMMAND_ACK" for m in got), [bytes(m.get_msgbuf()) for m in got]


@pytest.mark.timeout(120)
def test_serve_starts_signed_with_the_key_and_keeps_it_for_the_next_start(tmp_path: Path):
    key_file = tmp_path / "key.hex"
    key_file.write_text(KEY.hex() + "\n")
    answered, frames = _arm_answered(tmp_path, ("--signing-key", str(key_file)), None)
    assert not answered  # an unsigned client cannot arm
    assert frames and all(signature_matches(f, KEY) for f in frames)  # but hears the signed telemetry
    stored = tmp_path / "mavlink" / "mavlink-signing-key.bin"
    assert stored.read_bytes()[:32] == KEY
    answered, _ = _arm_answered(tmp_path, (), KEY)  # the stored key, no option: a client with the key arms
    assert answered


@pytest.mark.parametrize("content", [b"", b"not a key", b"ab" * 31])
def test_a_file_without_a_key_is_one_sentence_and_status_2(tmp_path: Path, content: bytes):
    bad = tmp_path / "bad.key"
    bad.write_bytes(content)
    proc = _serve(tmp_path, "--signing-key", str(bad), "--port", "0", "--gcs-port", "0")
    _, err = proc.communicate(timeout=30)
    assert proc.returncode == 2
    assert err.strip().count("\n") == 0 and "--signing-key" in err and "32 bytes" in err
    assert not (tmp_path / "mavlink").exists()
