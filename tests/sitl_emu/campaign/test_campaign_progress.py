"""`sitl-emu campaign` in a log file or a CI job (issue 25): a progress line at least every 10 s when stderr is no
terminal, and Ctrl-C ends with the summary so far and the command that resumes, not click's bare "Aborted!"."""

from __future__ import annotations

import io
import os
import shlex
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from click.testing import CliRunner
from support import REPO_ROOT, campaign_scenarios

from sitl_emu.campaign.progress import ProgressLines, duration_text
from sitl_emu.cli.main import main as sitl_emu_main

SCENARIOS = Path(campaign_scenarios.__file__).resolve()


def test_progress_lines_come_every_interval_from_a_thread_and_once_at_the_end() -> None:
    stream = io.StringIO()
    with ProgressLines(stream, total=4, every_s=0.05) as lines:
        lines.update(1)
        lines.row({"passed": True})
        time.sleep(0.3)  # no case finishes meanwhile: the lines still come
    printed = stream.getvalue().splitlines()
    assert len(printed) >= 3
    assert all(line.startswith("cases: 1 of 4 done (1 passed, 0 failed), ") for line in printed)
    assert printed[-1].endswith(" left")


def test_a_progress_line_says_done_of_total_passed_failed_rate_and_time_left() -> None:
    now = [100.0]
    lines = ProgressLines(io.StringIO(), total=10, clock=lambda: now[0])
    assert lines.line() == "cases: 0 of 10 done (0 passed, 0 failed), time left unknown"
    now[0] = 120.0
    lines.update(4)
    for passed in (True, True, True, False):
        lines.row({"passed": passed})
    assert lines.line() == "cases: 4 of 10 done (3 passed, 1 failed), 0.2 cases/s, about 30 s left"
    lines.update(6)
    assert lines.line() == "cases: 10 of 10 done (3 passed, 1 failed), 0.5 cases/s"
    assert (duration_text(20), duration_text(400), duration_text(7500)) == ("20 s", "7 min", "2 h 05 min")


def test_without_a_terminal_the_campaign_prints_progress_lines_not_a_bare_label(tmp_path: Path) -> None:
    result = CliRunner().invoke(sitl_emu_main, ["campaign", "--scenario", f"{SCENARIOS}:hover", "--seed", "1",
                                                    "--seed", "2", "--out", "-", "--engine", "serial"],
                                prog_name="sitl-emu")
    assert result.exit_code == 0, result.output
    assert result.stderr.splitlines()[-1].startswith("cases: 2 of 2 done (2 passed, 0 failed), ")


@pytest.mark.slow
def test_ctrl_c_prints_the_summary_so_far_and_the_command_that_resumes(tmp_path: Path) -> None:
    hold, out = tmp_path / "hold", tmp_path / "out.csv"
    hold.write_text("")
    args = ["campaign", "--scenario", f"{SCENARIOS}:misbehave", "--seed", "0", "--seed", "1", "--seed", "2",
            "--option", "bad_seeds=[1]", "--option", "behave=wait_for_file", "--option", f'wait_file="{hold}"',
            "--out", str(out), "--engine", "serial"]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO_ROOT), os.environ.get("PYTHONPATH", "")])}
    proc = subprocess.Popen([sys.executable, "-m", "sitl_emu", *args], cwd=tmp_path, env=env, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 60
        while not (out.exists() and len(out.read_text().splitlines()) == 2):  # c0000 done, c0001 waiting
            assert time.monotonic() < deadline and proc.poll() is None, proc.communicate()
            time.sleep(0.05)
        proc.send_signal(signal.SIGINT)
        stdout, stderr = proc.communicate(timeout=30)
    finally:
        proc.kill()
    assert proc.returncode == 130, stderr
    assert "Aborted!" not in stderr and "Traceback" not in stderr
    assert stdout.startswith("interrupted (Ctrl-C) after 1 of the 3 cases this run was to fly.\n\n"
                             "1 of 1 cases passed (100.0 %)\n")
    assert f"results so far: {out}\nresume (the cases in {out} are not flown again):\n  sitl-emu campaign " in stdout
    resume = shlex.split(stdout.strip().splitlines()[-1])
    assert resume[resume.index("--out") + 1] == str(out) and sorted(resume[2:]) == sorted(args[1:])
    before = out.read_text()
    hold.unlink()
    again = CliRunner().invoke(sitl_emu_main, resume[1:], prog_name="sitl-emu")
    assert again.exit_code == 0 and "3 of 3 cases passed" in again.output, again.output
    assert out.read_text().startswith(before) and len(out.read_text().splitlines()) == 4  # c0000 not flown again
