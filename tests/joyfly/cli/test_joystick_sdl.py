"""`joyfly joystick list` and `joyfly joystick test` with SDL virtual devices (read by SDL exactly like hardware)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from click.testing import CliRunner
from support import REPO_ROOT
from support.sdl_virtual import RIGHT_Y, VirtualPad

from joyfly.cli.joystick import joystick
from joyfly.sticks.sdl.api import sdl_api


@pytest.fixture
def pads() -> Iterator[list[VirtualPad]]:
    made: list[VirtualPad] = []
    yield made
    for pad in made:
        pad.detach()


def test_list_shows_sdl_devices_and_js_devices(pads: list[VirtualPad], tmp_path: Path) -> None:
    pads.append(VirtualPad.controller("List Pad", product=0x41))
    pads.append(VirtualPad.joystick("List Stick", naxes=3, nbuttons=5, nhats=1, product=0x42))
    pads.append(VirtualPad.controller("Quiet Pad", product=0x43, rumble=False))
    os.mkfifo(tmp_path / "js0")
    result = CliRunner().invoke(joystick, ["list", "--dev-dir", str(tmp_path)])
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    pad = next(ln for ln in lines if "\"List Pad\"" in ln)
    guid = sdl_api().device(pads[0].index).guid
    assert pad == (f"sdl:{pads[0].index}  \"List Pad\"  game controller  GUID {guid}  6 axes, 15 buttons, 0 hats, "
                   "rumble  profile: sdl-gamecontroller")
    stick = next(ln for ln in lines if "\"List Stick\"" in ln)
    assert "  joystick  " in stick and "3 axes, 5 buttons, 1 hats, no rumble" in stick
    calibrate = f"`joyfly joystick calibrate --joy sdl:{pads[1].index}`"
    assert stick.endswith(f"profile: none (joyfly fly refuses it: {calibrate})")
    assert "no rumble" in next(ln for ln in lines if "\"Quiet Pad\"" in ln)
    assert lines[-1].startswith(f"{tmp_path / 'js0'}  ")


@pytest.mark.slow
def test_test_shows_a_game_controllers_live_values(pads: list[VirtualPad]) -> None:
    pads.append(VirtualPad.controller("Test Pad", product=0x44))

    def move() -> None:
        time.sleep(0.3)
        pads[0].axis(RIGHT_Y, -1.0)

    mover = threading.Thread(target=move)
    mover.start()
    result = CliRunner().invoke(joystick, ["test", "--joy", "sdl:test", "--duration", "1.0"])
    mover.join()
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    assert lines[0].startswith("--joy sdl:test chose sdl:") and "\"Test Pad\"" in lines[0]
    assert lines[1].startswith("Test Pad (SDL game controller) (sdl:")
    assert lines[1].endswith("), profile sdl-gamecontroller")
    assert any("forward=+1.00" in ln and "axes=[0, 0, 0, -32767, 0, 0]" in ln for ln in lines[2:]), result.output


def test_sigterm_still_ends_joystick_test_with_sdl_loaded() -> None:
    """SDL would turn SIGTERM into an SDL_QUIT event nobody reads (SDL_HINT_NO_SIGNAL_HANDLERS keeps it away)."""
    proc = subprocess.Popen([sys.executable, str(REPO_ROOT / "tests" / "support" / "sdl_pilot.py"), "--", "joystick",
                             "test", "--joy", "sdl"], cwd=REPO_ROOT, stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert proc.stdout is not None
        assert "Pilot Pad" in proc.stdout.readline()  # running, SDL loaded
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(10.0) == -signal.SIGTERM
    finally:
        proc.kill()
        proc.communicate()
