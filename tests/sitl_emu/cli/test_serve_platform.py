"""`sitl-emu serve` and `sitl-emu campaign` where the POSIX-only modules and names do not exist (as on Windows):
termios, fcntl, tty, pty, readline and resource cannot be imported, and os/signal lack job control, process groups,
CPU affinity and SIGALRM. Each runs its main path to the end with no traceback. CI runs Linux: this is how the other
side of each platform seam is run there."""

from __future__ import annotations

import os
import select
import subprocess
import sys
import time
from pathlib import Path

import pytest
from support import REPO_ROOT, campaign_scenarios
from support.ports import free_udp_ports

WITHOUT_POSIX = """\
import os, signal, sys
for m in ('fcntl', 'termios', 'tty', 'pty', 'readline', 'resource'):
    sys.modules[m] = None
for module, names in ((os, ('tcgetpgrp', 'getpgrp', 'sched_getaffinity', 'killpg', 'setsid')),
                      (signal, ('SIGTTIN', 'SIGTTOU', 'SIGALRM', 'SIGHUP', 'setitimer', 'pthread_sigmask'))):
    for name in names:
        if hasattr(module, name):
            delattr(module, name)
from sitl_emu.__main__ import main
sys.argv = ['sitl-emu', *sys.argv[1:]]
main()
"""


def _sitl_emu(cwd: Path, *args: str, stdin: str = "") -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO_ROOT), os.environ.get("PYTHONPATH", "")])}
    return subprocess.run([sys.executable, "-c", WITHOUT_POSIX, *args], cwd=cwd, env=env, input=stdin,
                          capture_output=True, text=True, timeout=120)


def _clean(result: subprocess.CompletedProcess[str]) -> None:
    assert "Traceback" not in result.stderr and "Error" not in result.stderr, result.stderr


@pytest.mark.parametrize("command", ["serve", "campaign"])
def test_the_help_shows_without_posix(command: str, tmp_path: Path) -> None:
    result = _sitl_emu(tmp_path, command, "--help")
    _clean(result)
    assert result.returncode == 0 and f"Usage: sitl-emu {command}" in result.stdout


def _read_until(fd: int, text: str, timeout_s: float = 60.0) -> str:
    seen = b""
    deadline = time.monotonic() + timeout_s
    while text.encode() not in seen and time.monotonic() < deadline:
        if select.select([fd], [], [], 0.1)[0]:
            try:
                seen += os.read(fd, 4096)
            except OSError:  # the child closed its side
                break
    return seen.decode(errors="replace")


@pytest.mark.skipif(not hasattr(os, "openpty"), reason="gives the child a terminal through a pty (CI is Linux)")
def test_serve_starts_its_console_on_a_terminal_and_stops_without_posix(tmp_path: Path) -> None:
    api_port, gcs_port, remote, gcs_remote = free_udp_ports(4)
    master, slave = os.openpty()
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO_ROOT), os.environ.get("PYTHONPATH", "")])}
    proc = subprocess.Popen([sys.executable, "-c", WITHOUT_POSIX, "serve", "--no-log", "--port", str(api_port),
                             "--gcs-port", str(gcs_port), "--remote", f"127.0.0.1:{remote}", "--gcs-remote",
                             f"127.0.0.1:{gcs_remote}"], cwd=tmp_path, env=env, stdin=slave, stdout=slave,
                            stderr=subprocess.PIPE, text=True)
    os.close(slave)
    try:
        started = _read_until(master, "pxh> ")
        assert "PX4 quadrotor sysid 1" in started and "pxh> " in started, started
        os.write(master, b"ver all\n")
        assert "HW arch: PX4_SITL" in _read_until(master, "HW arch"), "the console did not answer"
        os.write(master, b"shutdown\n")
        assert "Exiting NOW." in _read_until(master, "Exiting NOW.")  # pxh shutdown
        _, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
        os.close(master)
    assert proc.returncode == 0 and "Traceback" not in err and "Error" not in err, err


def test_a_serial_campaign_runs_without_posix(tmp_path: Path) -> None:
    scenarios = Path(campaign_scenarios.__file__).resolve()
    cases = tmp_path / "cases.toml"
    cases.write_text(f'scenario = "{scenarios}:misbehave"\n[limits]\nsim_s = 5.0\nwall_s = 0.5\n'
                     '[fixed]\noptions = { bad_seeds = [1], behave = "slow_steps" }\n[grid]\nseed = [0, 1]\n')
    result = _sitl_emu(tmp_path, "campaign", str(cases), "--out", str(tmp_path / "out.csv"), "--engine", "serial",
                       "--no-progress")
    _clean(result)
    assert result.returncode == 1, result.stdout + result.stderr  # the slow case failed, and nothing else
    assert "1 of 2 cases passed (50.0 %): 1 timeout" in result.stdout, result.stdout
