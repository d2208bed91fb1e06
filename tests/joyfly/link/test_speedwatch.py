"""joyfly notices when the vehicle's clock does not run at its --speed, and says so once (issue 10.11)."""

from __future__ import annotations

import os
import select
import subprocess
import sys
import time
from pathlib import Path
from types import SimpleNamespace

import pytest
from support import REPO_ROOT
from support.ports import free_udp_ports

from joyfly.link.speedwatch import WINDOW_S, SpeedWatch, mismatch_sentence

REPO = REPO_ROOT


class FakeWall:
    def __init__(self) -> None:
        self.now_s = 100.0

    def __call__(self) -> float:
        return self.now_s


def feed(watch: SpeedWatch, wall: FakeWall, vehicle_speed: float, seconds: float, start_ms: int = 5000) -> None:
    """Messages every 0.1 wall s stamped with a vehicle clock running at vehicle_speed."""
    for i in range(int(seconds * 10) + 1):
        wall.now_s = 100.0 + i * 0.1
        watch.observe(SimpleNamespace(time_boot_ms=start_ms + int(i * 100 * vehicle_speed)))


@pytest.mark.parametrize(("vehicle", "joyfly", "warned"), [
    (1.0, 1.0, False), (10.0, 10.0, False), (4.0, 1.0, True), (1.0, 4.0, True), (0.5, 1.0, True),
    (0.85, 1.0, False),  # a busy machine running the vehicle a little slow is not worth a warning
])
def test_warns_once_when_the_vehicle_runs_at_another_speed(vehicle: float, joyfly: float, warned: bool) -> None:
    wall, said = FakeWall(), list[str]()
    watch = SpeedWatch(joyfly, said.append, wall)
    feed(watch, wall, vehicle, 2 * WINDOW_S)
    assert watch.measured == pytest.approx(vehicle, rel=0.02)
    assert len(said) == (1 if warned else 0)
    if warned:
        assert f"about {vehicle:g} times real time but joyfly at --speed {joyfly:g}" in said[0]
        assert f"restart joyfly with --speed {vehicle:g}" in said[0]


def test_judges_only_after_the_window_and_ignores_messages_without_a_timestamp() -> None:
    wall, said = FakeWall(), list[str]()
    watch = SpeedWatch(1.0, said.append, wall)
    watch.observe(SimpleNamespace(type=2))  # a HEARTBEAT has no time_boot_ms
    feed(watch, wall, 10.0, WINDOW_S - 0.5)
    assert watch.measured is None and not said


def test_a_reboot_restarts_the_measurement() -> None:
    wall, said = FakeWall(), list[str]()
    watch = SpeedWatch(1.0, said.append, wall)
    feed(watch, wall, 1.0, 1.0, start_ms=900_000)
    feed(watch, wall, 1.0, 2 * WINDOW_S, start_ms=0)  # time_boot_ms went back: the vehicle rebooted
    assert watch.measured == pytest.approx(1.0, rel=0.02) and not said


def test_the_sentence_rounds_and_never_uses_exponents() -> None:
    assert "about 100 times" in mismatch_sentence(99.7, 1.0)
    assert "about 0.33 times" in mismatch_sentence(0.3333, 1.0)
    assert "stood still" in mismatch_sentence(0.0, 1.0)


def _read_until(proc: subprocess.Popen[str], text: str, timeout_s: float) -> str:
    assert proc.stdout is not None
    seen, end = "", time.monotonic() + timeout_s
    while time.monotonic() < end and text not in seen:
        ready, _, _ = select.select([proc.stdout], [], [], 0.5)
        if ready:
            line = proc.stdout.readline()
            if not line:
                break
            seen += line
    return seen


@pytest.mark.slow
def test_joyfly_warns_when_serve_runs_faster_than_its_speed(tmp_path: Path) -> None:
    """sitl-emu serve --speed 4 and joyfly fly without --speed, as a user would start them."""
    joy_port, emu_port, gcs_port = free_udp_ports(3)
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    emu = subprocess.Popen([sys.executable, "-m", "sitl_emu", "serve", "--port", str(emu_port), "--remote",
                            f"127.0.0.1:{joy_port}", "--gcs-port", str(gcs_port), "--speed", "4", "--no-console"],
                           cwd=tmp_path, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                           env=env)
    script = tmp_path / "still.txt"
    script.write_text("0 forward=0\n+60 end\n")
    joy = subprocess.Popen([sys.executable, "-m", "joyfly", "fly", "--joy", f"script:{script}", "--url",
                            f"udp://127.0.0.1:{joy_port}@127.0.0.1:{emu_port}"],
                           stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
                           env=env)
    try:
        seen = _read_until(joy, "times real time but joyfly at --speed 1", 30.0)
    finally:
        for proc in (joy, emu):
            proc.kill()
            proc.wait()
    assert "times real time but joyfly at --speed 1: restart joyfly with --speed" in seen, seen
    warning = next(line for line in seen.splitlines() if "times real time" in line)
    measured = float(warning.split("runs at about ")[1].split()[0])
    assert 3.0 <= measured <= 4.5, warning
