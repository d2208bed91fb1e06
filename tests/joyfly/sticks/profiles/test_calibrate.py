"""`joyfly joystick calibrate`'s wizard driven by SDL virtual devices: the profile it learns (axes, reversed axes,
a radio's resting throttle, deadzones, buttons), the file it writes, and that joyfly then flies the device with it."""

from __future__ import annotations

import io
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from click.testing import CliRunner
from support.calibration_user import CalibrationUser
from support.sdl_virtual import VirtualPad

from joyfly.cli.calibrate import TerminalConsole
from joyfly.cli.joystick import joystick
from joyfly.sticks.js.reader import JoystickError
from joyfly.sticks.mapping import open_sticks
from joyfly.sticks.profiles.calibrate import Wizard
from joyfly.sticks.profiles.user import load_user_profiles, profile_toml, write_user_profile
from joyfly.sticks.sources import open_source
from joyfly.types import Action
from px4common.clock import WallClock

# a stick with its axes in an odd order: throttle on 3 (centred), yaw 0, pitch 2 (forward = negative), roll 1
#  (right = negative: reversed)
GAMEPADISH = {"up": (3, -1.0, 0.0), "yaw": (0, 1.0, 0.0), "forward": (2, -1.0, 0.0), "right": (1, -1.0, 0.0)}
BUTTONS = {"arm": 5, "takeoff": 2, "land": 0, "offboard": 7}


@pytest.fixture
def pads() -> Iterator[list[VirtualPad]]:
    made: list[VirtualPad] = []
    yield made
    for pad in made:
        pad.detach()


def calibrate(pad: VirtualPad, spec: str, layout: dict[str, tuple[int, float, float]], buttons: dict[str, int]):
    source = open_source(spec, WallClock()).source
    try:
        user = CalibrationUser(pad, layout, buttons)
        return Wizard(source, user).run(), source.name, str(getattr(source, "guid", ""))
    finally:
        source.close()


@pytest.mark.slow
def test_the_wizard_learns_axes_reversals_and_buttons(pads: list[VirtualPad]) -> None:
    pads.append(VirtualPad.joystick("Wizard Stick", naxes=4, nbuttons=8, nhats=0, product=0x51))
    profile, _, _ = calibrate(pads[0], "sdl:wizard", GAMEPADISH, BUTTONS)
    axes = {role: (a.index, a.invert) for role, a in profile.axes.items()}
    assert axes == {"up": (3, True), "yaw": (0, False), "forward": (2, True), "right": (1, True)}
    assert all(0.05 <= a.deadzone <= 0.3 for a in profile.axes.values())
    assert dict(profile.buttons) == {Action.ARM: 5, Action.TAKEOFF: 2, Action.LAND: 0, Action.OFFBOARD: 7}


@pytest.mark.slow
def test_a_radio_throttle_resting_at_one_end_is_a_non_centring_throttle(pads: list[VirtualPad]) -> None:
    pads.append(VirtualPad.joystick("Wizard Radio", naxes=4, nbuttons=8, nhats=0, product=0x52))
    radio = {"up": (2, 1.0, -1.0), "yaw": (3, 1.0, 0.0), "forward": (1, 1.0, 0.0), "right": (0, 1.0, 0.0)}
    profile, _, _ = calibrate(pads[0], "sdl:radio", radio, {})
    assert profile.axis("up") is None
    throttle = profile.axis("throttle_abs")
    assert throttle is not None and (throttle.index, throttle.invert) == (2, False)
    assert profile.axis("forward").invert is False and not profile.buttons  # type: ignore[union-attr]


@pytest.mark.slow
def test_the_written_profile_is_the_one_joyfly_then_flies_with(pads: list[VirtualPad], tmp_path: Path,
                                                               monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("JOYFLY_PROFILES", str(tmp_path))
    pads.append(VirtualPad.joystick("Wizard Stick Two", naxes=4, nbuttons=8, nhats=0, product=0x53))
    with pytest.raises(JoystickError, match="joyfly joystick calibrate"):
        open_sticks("sdl:two", WallClock())  # refused before
    profile, name, guid = calibrate(pads[0], "sdl:two", GAMEPADISH, BUTTONS)
    path = write_user_profile(profile_toml(name, guid, profile), name)
    assert path.parent == tmp_path and [p.device_name for p in load_user_profiles()] == ["Wizard Stick Two"]
    listed = CliRunner().invoke(joystick, ["list", "--dev-dir", str(tmp_path)])
    assert any("\"Wizard Stick Two\"" in ln and ln.endswith("profile: calibrated:wizard-stick-two")
               for ln in listed.output.splitlines()), listed.output
    sticks = open_sticks("sdl:two", WallClock())
    try:
        assert sticks.profile.name == "calibrated:wizard-stick-two"
        pads[0].axis(2, -0.6)  # the stick calibrated as pitch, pushed forward
        pads[0].axis(1, -0.6)  # roll: reversed, so this is right
        cmd = sticks.poll(0.2)
        assert cmd.forward > 0.5 and cmd.right > 0.5
        pads[0].button(5, True)
        assert sticks.poll(0.2).pressed == {Action.ARM}
    finally:
        sticks.close()


def test_a_bad_profile_file_is_one_sentence(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("JOYFLY_PROFILES", str(tmp_path))
    (tmp_path / "broken.toml").write_text("[profile]\nforward = 3\n")
    with pytest.raises(JoystickError, match="is not a joyfly profile"):
        load_user_profiles()


def test_the_terminal_console_takes_enter_per_prompt_and_everything_once_stdin_closes(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    lines = threading.Semaphore(0)

    class Keyboard(io.StringIO):
        def __iter__(self):  # type: ignore[override]
            lines.acquire()
            yield "\n"  # one Enter
            lines.acquire()  # then the user closes stdin

    monkeypatch.setattr("sys.stdin", Keyboard())
    console = TerminalConsole()
    console.say("first prompt")
    assert not console.entered()
    lines.release()
    deadline = time.monotonic() + 5.0
    while not console.entered() and time.monotonic() < deadline:
        time.sleep(0.01)
    assert console.entered()
    console.say("second prompt")  # a new prompt forgets the earlier Enter
    assert not console.entered()
    lines.release()
    while not console.entered() and time.monotonic() < deadline:
        time.sleep(0.01)
    console.say("third prompt")
    assert console.entered()  # stdin closed: every prompt counts as answered
    assert capsys.readouterr().out.splitlines() == ["first prompt", "second prompt", "third prompt"]
