"""`sitl-emu serve` on a terminal, as a user runs it from an interactive shell (tests/pty_job.py plays the shell).

- `serve &` (a background job) must not stop on reading the terminal ("Stopped (tty input)") and must end on
  SIGTERM at once; `fg` later gives it the console, `bg` takes it away again.
- Ctrl-C and SIGTERM print PX4's shutdown line "PX4 Exiting..." (platforms/posix/src/px4/common/main.cpp).
- The pxh> console edits lines with readline: Up recalls the last command instead of printing "^[[A".
- With --count the console says which vehicle it controls, and `vehicle <sysid>` switches.
"""

from __future__ import annotations

import signal
import time

import pytest
from support.ports import free_udp_ports
from support.pty_job import PtyJob

pytestmark = pytest.mark.slow  # processes or long flights: not in `make test-fast`

SHUTDOWN_LINE = "PX4 Exiting..."
UP = "\x1b[A"


def _ports_args() -> list[str]:
    api, gcs, remote = free_udp_ports(3)
    while any(p + 3 >= 65536 for p in (api, gcs, remote)):  # room for --count 3's offset ports
        api, gcs, remote = free_udp_ports(3)
    return ["--port", str(api), "--gcs-port", str(gcs), "--remote", f"127.0.0.1:{remote}",
            "--gcs-remote", f"127.0.0.1:{remote}"]


def _run(job: PtyJob, line: str, expect: str, count: int = 1) -> None:
    """Type `line` and Enter; `expect` shows up (for the `count`-th time)."""
    job.send(line + "\n")
    assert job.wait_for(expect, count=count), job.output


def _ctrl_z(job: PtyJob) -> None:
    job.send("\x1a")  # Ctrl-Z: the terminal stops the foreground job
    time.sleep(0.5)
    assert job.state() == "T"


@pytest.fixture()
def jobs(tmp_path):
    started: list[PtyJob] = []

    def start(foreground: bool, *args: str, readline: bool = True) -> PtyJob:
        job = PtyJob([*_ports_args(), *args], foreground, tmp_path, readline)
        started.append(job)
        assert job.wait_for("sitl-emu: PX4 quadrotor sysid"), job.output
        return job

    yield start
    for job in started:
        job.close()


def test_background_job_keeps_running_and_ends_on_sigterm_with_the_shutdown_line(jobs):
    job = jobs(False)
    time.sleep(1.0)  # a console reading the terminal would have been stopped by SIGTTIN by now
    assert job.state() != "T", "serve & stopped (tty input)"
    assert "pxh> " not in job.output  # no prompt for a background job
    started = time.monotonic()
    job.kill(signal.SIGTERM)
    assert job.wait(timeout=5) == 0
    assert time.monotonic() - started < 2.0
    assert job.wait_for(SHUTDOWN_LINE, timeout=2), job.output


def test_fg_gives_the_console_and_bg_takes_it_away(jobs):
    job = jobs(False)
    time.sleep(0.5)
    job.fg()
    assert job.wait_for("pxh> "), job.output
    _run(job, "ver", "HW arch: PX4_SITL")
    job.bg()
    time.sleep(1.0)
    assert job.state() != "T"
    job.fg()
    _run(job, "listener vehicle_status", "TOPIC: vehicle_status")


def test_readline_up_arrow_recalls_the_last_command(jobs):
    job = jobs(True)
    assert job.wait_for("pxh> "), job.output
    job.send("ve")  # the log line that comes meanwhile goes above the prompt, which is drawn again with "ve"
    assert job.wait_for("INFO  [commander] Ready for takeoff!\r\npxh> ve"), job.output
    _run(job, "r", "HW arch: PX4_SITL")
    job.send(UP + "\n")
    assert job.wait_for("HW arch: PX4_SITL", count=2), job.output
    assert "^[[A" not in job.output
    job.send("\x04")  # Ctrl-D: ignored, as by pxh; the console goes on
    time.sleep(0.3)
    _run(job, "ver", "HW arch: PX4_SITL", count=3)


def test_ctrl_c_on_the_console_prints_the_shutdown_line_and_exits_0(jobs):
    job = jobs(True)
    assert job.wait_for("pxh> "), job.output
    job.send("\x03")  # the terminal turns it into SIGINT for the foreground job
    assert job.wait(timeout=5) == 0
    assert job.wait_for(SHUTDOWN_LINE, timeout=2), job.output
    assert "Traceback" not in job.output


def test_console_says_which_vehicle_it_controls_and_switches(jobs):
    job = jobs(True, "--count", "3")
    assert job.wait_for("console controls sysid 1 (vehicle 1 of 3, sysids 1-3)"), job.output
    _run(job, "vehicle 2", "console controls sysid 2")
    _run(job, "listener vehicle_status", "    system_id: 2")


def test_ctrl_z_bg_leaves_the_terminal_to_the_shell_and_fg_brings_the_console_back(jobs):
    job = jobs(True)
    assert job.wait_for("pxh> "), job.output
    _ctrl_z(job)
    job.bg()
    time.sleep(0.5)
    assert job.state() != "T"
    _run(job, "echo typed-for-the-shell", "shell read: echo typed-for-the-shell")
    time.sleep(0.5)
    assert job.state() != "T" and "Invalid command: echo" not in job.output
    job.fg()
    _run(job, "ver", "HW arch: PX4_SITL")


def test_sigterm_to_a_stopped_job_ends_it_with_the_shutdown_line(jobs):
    job = jobs(True)
    assert job.wait_for("pxh> "), job.output
    _ctrl_z(job)
    job.kill(signal.SIGTERM)  # as bash's `kill %1`: SIGTERM, then SIGCONT so the job can act on it
    job.kill(signal.SIGCONT)
    assert job.wait(timeout=5) == 0
    assert job.wait_for(SHUTDOWN_LINE, timeout=2), job.output


def test_without_readline_the_console_still_works_and_still_minds_job_control(jobs):
    job = jobs(False, readline=False)
    time.sleep(1.0)
    assert job.state() != "T" and "pxh> " not in job.output
    job.fg()
    assert job.wait_for("pxh> "), job.output
    _run(job, "ver", "HW arch: PX4_SITL")
    job.send("\x04")  # Ctrl-D: ignored, as by pxh
    time.sleep(0.3)
    _run(job, "ver", "HW arch: PX4_SITL", count=2)
    job.bg()
    time.sleep(0.5)
    _run(job, "echo typed-for-the-shell", "shell read: echo typed-for-the-shell")
    job.kill(signal.SIGTERM)
    assert job.wait(timeout=5) == 0
    assert job.wait_for(SHUTDOWN_LINE, timeout=2), job.output
    assert "Invalid command: echo" not in job.output
