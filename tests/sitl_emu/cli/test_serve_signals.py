"""SIGINT and SIGTERM end `sitl-emu serve` the same way in every phase: during its imports and start-up as after it,
also when it was started with SIGINT ignored, as a script's background job is (`sitl-emu serve & ...; kill -INT $!`):
it exits at once with PX4's "PX4 Exiting..." and status 0, as PX4 SITL does (main.cpp register_sig_handler)."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from support import REPO_ROOT
from support.ports import free_udp_ports

pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="reads /proc/PID/status (Linux)")]


def _ignore_sigint() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # what a non-interactive shell does for `cmd &`


def _serve(workdir: Path) -> subprocess.Popen[str]:
    api_port, gcs_port, remote, gcs_remote = free_udp_ports(4)
    args = [sys.executable, "-m", "sitl_emu", "serve", "--no-console", "--no-log", "--port", str(api_port),
            "--gcs-port", str(gcs_port), "--remote", f"127.0.0.1:{remote}", "--gcs-remote", f"127.0.0.1:{gcs_remote}"]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO_ROOT), os.environ.get("PYTHONPATH", "")])}
    return subprocess.Popen(args, cwd=workdir, env=env, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, preexec_fn=_ignore_sigint)


def _caught(pid: int, sig: int) -> bool:
    """Whether process `pid` has a handler for `sig` (the SigCgt mask of /proc/PID/status)."""
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return False
    mask = next(line.split()[1] for line in status.splitlines() if line.startswith("SigCgt:"))
    return bool(int(mask, 16) >> (sig - 1) & 1)


def _signal_as_soon_as_caught(proc: subprocess.Popen[str], sig: int) -> None:
    deadline = time.monotonic() + 20
    while not _caught(proc.pid, sig):
        assert proc.poll() is None and time.monotonic() < deadline, "serve never took the signal in hand"
        time.sleep(0.0005)
    proc.send_signal(sig)


def _ended(proc: subprocess.Popen[str]) -> str:
    """serve's output once it has ended by itself, cleanly and promptly."""
    try:
        out, err = proc.communicate(timeout=15)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.communicate()
        pytest.fail("serve did not end within 15 s of the signal")
    assert proc.returncode == 0 and err == "", err
    assert out.endswith("\nPX4 Exiting...\n"), out
    return out


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_during_the_imports_ends_serve_before_it_opens_a_port(sig: int, tmp_path: Path) -> None:
    proc = _serve(tmp_path)
    _signal_as_soon_as_caught(proc, sig)  # sitl_emu/__main__.py's first line: the imports are still to come
    assert "PX4 quadrotor" not in _ended(proc)  # stopped before its links opened


def test_sigint_after_start_up_ends_serve_though_started_with_it_ignored(tmp_path: Path) -> None:
    proc = _serve(tmp_path)
    assert proc.stdout is not None
    assert "PX4 quadrotor sysid 1" in proc.stdout.readline()  # up and running
    assert proc.stdout.readline().startswith("sitl-emu: core: ")  # which build runs
    time.sleep(0.2)
    proc.send_signal(signal.SIGINT)
    assert _ended(proc).startswith("\nPX4 Exiting")  # what is left after the first line


@pytest.mark.skipif(shutil.which("sh") is None, reason="needs a POSIX shell")
def test_a_script_that_starts_serve_in_the_background_ends_it_with_kill_int(tmp_path: Path) -> None:
    """The issue's script, as written: the shell itself starts serve with SIGINT ignored."""
    api_port, gcs_port, remote, gcs_remote = free_udp_ports(4)
    script = (f"{sys.executable} -m sitl_emu serve --no-console --no-log --port {api_port} --gcs-port {gcs_port} "
              f"--remote 127.0.0.1:{remote} --gcs-remote 127.0.0.1:{gcs_remote} & sleep 0.4; kill -INT $!; wait $!; "
              "echo status $?")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO_ROOT), os.environ.get("PYTHONPATH", "")])}
    done = subprocess.run(["sh", "-c", script], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=30)
    assert done.stdout.endswith("PX4 Exiting...\nstatus 0\n"), done.stdout + done.stderr
