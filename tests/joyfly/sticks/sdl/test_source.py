"""The SDL source read through SDL's virtual devices (which SDL reads exactly like hardware): choosing the device
(`sdl`, `sdl:N`, `sdl:NAME`, `auto`), the standard layout and the sdl-gamecontroller profile, plain joysticks and
their profiles, hot-plug (same GUID resumes, another device is never taken), mappings, rumble."""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path

import pytest
from support.sdl_virtual import BACK, LEFT_Y, RIGHT_X, RIGHT_Y, START, A, VirtualPad, Y

from joyfly.sticks.js.reader import JoystickError
from joyfly.sticks.mapping import open_sticks
from joyfly.sticks.sdl.api import SdlUnavailable, sdl_api
from joyfly.sticks.sdl.mappings import SdlMappings
from joyfly.sticks.sdl.source import SdlSource
from joyfly.sticks.sources import open_source
from joyfly.types import Action


class Clock:
    def __init__(self) -> None:
        self.t = 0.0

    def now(self) -> float:
        return self.t

    def sleep(self, seconds: float) -> None:
        self.t += seconds


@pytest.fixture
def pads() -> Iterator[list[VirtualPad]]:
    made: list[VirtualPad] = []
    yield made
    for pad in made:
        pad.detach()


def test_sdl_takes_the_first_game_controller_and_flies_it_in_the_standard_layout(pads: list[VirtualPad]) -> None:
    pads.append(VirtualPad.joystick("Some Flight Stick"))
    pads.append(VirtualPad.controller("Virtual Pad"))
    sticks = open_sticks("sdl", Clock())
    try:
        assert sticks.profile.name == "sdl-gamecontroller"
        assert "the first SDL game controller" in sticks.why and "Virtual Pad" in sticks.why
        pad = pads[1]
        pad.axis(RIGHT_Y, -0.5)  # right stick pushed forward (SDL: up is negative)
        pad.axis(RIGHT_X, 0.25)
        pad.axis(LEFT_Y, -1.0)  # throttle stick up
        pad.button(Y, True)
        cmd = sticks.poll(0.2)
        assert cmd.forward == pytest.approx((0.5 - 0.05) / 0.95, abs=1e-3)
        assert cmd.right == pytest.approx((0.25 - 0.05) / 0.95, abs=1e-3)
        assert cmd.up == pytest.approx(1.0, abs=1e-3) and cmd.yaw == 0.0
        assert cmd.pressed == {Action.TAKEOFF}
        pad.button(Y, False)
        for button, action in ((A, Action.LAND), (START, Action.ARM), (BACK, Action.OFFBOARD)):
            pad.button(button, True)
            assert sticks.poll(0.2).pressed == {action}
            pad.button(button, False)
    finally:
        sticks.close()


def test_a_stick_change_ends_the_wait_at_once(pads: list[VirtualPad]) -> None:
    pads.append(VirtualPad.controller())
    opened = open_source("sdl", Clock())
    source = opened.source
    assert isinstance(source, SdlSource)
    try:
        source.poll(0.0)
        pads[0].axis(RIGHT_Y, -1.0)
        state = source.poll(5.0)  # returns on the change, long before 5 s
        assert state.axes[RIGHT_Y] == -32767 and state.connected
    finally:
        source.close()


def test_device_by_index_and_by_name(pads: list[VirtualPad]) -> None:
    pads.append(VirtualPad.controller("Alpha Pad", product=0x10))
    pads.append(VirtualPad.controller("Bravo Pad", product=0x11))
    for spec, name in ((f"sdl:{pads[1].index}", "Bravo Pad"), ("sdl:bRaVo", "Bravo Pad"), ("sdl:alpha", "Alpha Pad")):
        source = open_source(spec, Clock()).source
        assert source.name.startswith(name), spec
        source.close()


def test_bad_specs_say_what_there_is_in_one_sentence(pads: list[VirtualPad]) -> None:
    with pytest.raises(JoystickError) as none:
        open_source("sdl", Clock())
    assert "No game controller is connected" in str(none.value) and "joyfly joystick list" in str(none.value)
    pads.append(VirtualPad.controller("Alpha Pad", product=0x10))
    pads.append(VirtualPad.controller("Bravo Pad", product=0x11))
    with pytest.raises(JoystickError) as seven:
        open_source("sdl:7", Clock())
    text = str(seven.value)
    assert text.startswith("There is no SDL device 7") and "\"Alpha Pad\"" in text and "\"Bravo Pad\"" in text
    assert text.endswith(".") and ". " not in text
    with pytest.raises(JoystickError, match="No SDL device's name contains \"charlie\""):
        open_source("sdl:charlie", Clock())


def test_auto_prefers_a_game_controller_then_a_joystick(pads: list[VirtualPad]) -> None:
    pads.append(VirtualPad.joystick("EdgeTX RadioMaster TX16S Joystick", naxes=8, nbuttons=24, nhats=0))
    opened = open_source("auto", Clock())
    assert "the first SDL joystick" in opened.why
    opened.source.close()
    pads.append(VirtualPad.controller("Virtual Pad"))
    opened = open_source("auto", Clock())
    assert "the first SDL game controller" in opened.why and "Virtual Pad" in opened.why
    opened.source.close()


def test_a_plain_joystick_flies_with_its_own_profile_and_hats_read_as_axes(pads: list[VirtualPad]) -> None:
    pads.append(VirtualPad.joystick("OpenTX FrSky Taranis Joystick", naxes=4, nbuttons=8, nhats=1))
    sticks = open_sticks("sdl:taranis", Clock())
    try:
        assert sticks.profile.name == "radio"
        pads[0].axis(1, 0.6)  # the radio profile: axis 1 = elevator, forward positive
        pads[0].hat(0, 8 | 1)  # left + up
        cmd = sticks.poll(0.2)
        assert cmd.forward > 0.5
        assert sticks.last_state is not None and sticks.last_state.axes[4:6] == (-32767, -32767)
    finally:
        sticks.close()


def test_an_unknown_plain_joystick_is_refused_until_described(pads: list[VirtualPad], tmp_path: Path) -> None:
    pads.append(VirtualPad.joystick("Mystery Stick 3000"))
    with pytest.raises(JoystickError) as err:
        open_sticks("sdl", Clock())  # no game controller at all
    assert "No game controller is connected" in str(err.value) and "Mystery Stick 3000" in str(err.value)
    with pytest.raises(JoystickError) as refused:
        open_sticks("sdl:mystery", Clock())
    text = str(refused.value)
    assert "not know as a game controller" in text and "--sdl-mapping" in text
    assert "`joyfly joystick calibrate --joy sdl:" in text
    described = open_sticks("sdl:mystery", Clock(), overrides={"forward": {"index": 1, "invert": True}})
    assert described.profile.axis("forward") is not None
    described.close()
    named = open_sticks("sdl:mystery", Clock(), profile="generic")
    assert named.profile.name == "generic"
    named.close()


def test_a_mapping_makes_a_plain_joystick_a_game_controller_with_that_layout(pads: list[VirtualPad],
                                                                            tmp_path: Path) -> None:
    pads.append(VirtualPad.joystick("Mapped Stick", naxes=4, nbuttons=8, nhats=0, product=0x77))
    guid = sdl_api().device(pads[0].index).guid
    db = tmp_path / "gamecontrollerdb.txt"
    # the right stick's axes swapped on purpose: axis 0 is "righty" here
    db.write_text("# my pads\n\n"
                  f"{guid},Mapped Stick,a:b0,b:b1,x:b2,y:b3,back:b4,start:b5,"
                  "leftx:a2,lefty:a3,rightx:a1,righty:a0,platform:Linux,\n"
                  "00000000000000000000000000000000,Other OS,a:b0,platform:Mac OS X,\n")
    sticks = open_sticks("sdl:mapped", Clock(), mappings=SdlMappings(str(db)))
    try:
        assert sticks.profile.name == "sdl-gamecontroller"
        pads[0].axis(0, -0.8)  # raw axis 0 pushed up: the mapping says that is the right stick forward
        cmd = sticks.poll(0.2)
        assert cmd.forward > 0.7 and cmd.right == 0.0
        pads[0].button(5, True)
        assert sticks.poll(0.2).pressed == {Action.ARM}  # start:b5
    finally:
        sticks.close()


def test_a_broken_mapping_file_names_the_file_and_line(tmp_path: Path) -> None:
    db = tmp_path / "db.txt"
    db.write_text("# header\n03000000de280000ff11000001000000,Steam Virtual Gamepad,a:b0,leftx:a0,\nnot a mapping\n")
    with pytest.raises(JoystickError) as err:
        open_source("sdl", Clock(), mappings=SdlMappings(str(db)))
    text = str(err.value)
    assert text.startswith(f"{db} line 3 is not an SDL game-controller mapping") and text.endswith(".")


def test_the_environment_mapping_is_checked_too(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SDL_GAMECONTROLLERCONFIG", "garbage line")
    with pytest.raises(JoystickError, match="SDL_GAMECONTROLLERCONFIG environment variable line 1"):
        open_source("sdl", Clock())


def test_unplugged_reports_disconnected_same_guid_resumes_another_is_ignored(pads: list[VirtualPad]) -> None:
    pads.append(VirtualPad.controller("Mine", product=0x21))
    source = open_source("sdl:mine", Clock()).source
    assert isinstance(source, SdlSource)
    try:
        assert source.poll(0.0).connected
        pads[0].detach()
        assert not source.poll(0.05).connected and "vanished" in str(source.last_error)
        pads.append(VirtualPad.controller("Somebody Else", product=0x22))
        pads[1].axis(RIGHT_Y, -1.0)
        state = source.poll(0.05)
        assert not state.connected and "Ignoring \"Somebody Else\"" in source.news[0]  # never taken over
        pads[0].reattach()
        pads[0].axis(RIGHT_Y, -0.5)
        state = source.poll(0.2)
        assert state.connected and state.axes[RIGHT_Y] == round(-0.5 * 32767) and source.last_error is None
    finally:
        source.close()


def test_rumble_reaches_a_pad_that_has_it_and_nothing_happens_on_one_without(pads: list[VirtualPad]) -> None:
    pads.append(VirtualPad.controller("Rumbler", product=0x31))
    pads.append(VirtualPad.controller("Quiet", product=0x32, rumble=False))
    loud = open_source("sdl:rumbler", Clock()).source
    quiet = open_source("sdl:quiet", Clock()).source
    assert isinstance(loud, SdlSource) and isinstance(quiet, SdlSource)
    try:
        assert loud.rumble(0.5, 1.0, 200) and pads[0].rumbles[0][:2] == (32768, 65535)
        assert not quiet.has_rumble and quiet.rumble(1.0, 1.0, 200) is False and pads[1].rumbles == []
    finally:
        loud.close()
        quiet.close()


def test_sdl_that_cannot_load_is_one_sentence_and_auto_reads_js(tmp_path: Path) -> None:
    def broken() -> object:
        raise SdlUnavailable("SDL2 could not be loaded (no library): use a /dev/input/js* device.")

    with pytest.raises(JoystickError, match="SDL2 could not be loaded"):
        open_source("sdl", Clock(), loader=broken)  # type: ignore[arg-type]
    fifo = tmp_path / "js0"
    os.mkfifo(fifo)
    opened = open_source("auto", Clock(), dev_dir=str(tmp_path), loader=broken)  # type: ignore[arg-type]
    assert opened.source.path == str(fifo) and "SDL2 could not be loaded" in opened.why
    opened.source.close()


def test_a_recorded_game_controller_replays_through_the_same_profile(pads: list[VirtualPad], tmp_path: Path) -> None:
    pads.append(VirtualPad.controller("Recorded Pad"))
    rec = tmp_path / "rec.jsonl"
    sticks = open_sticks("sdl", Clock(), record=str(rec))
    sticks.poll(0.0)
    sticks.close()
    replay = open_sticks(f"replay:{rec}", Clock())
    assert replay.profile.name == "sdl-gamecontroller" and replay.name == "Recorded Pad (SDL game controller)"
    replay.close()


def test_the_config_files_mappings_and_rumble_reach_the_options(pads: list[VirtualPad], tmp_path: Path) -> None:
    from joyfly.config import ConfigError, build_options, load_file

    pads.append(VirtualPad.joystick("Config Mapped Stick", naxes=4, nbuttons=8, nhats=0, product=0x78))
    guid = sdl_api().device(pads[0].index).guid
    path = tmp_path / "joyfly.toml"
    path.write_text(f'mappings = ["{guid},Config Mapped Stick,a:b0,start:b5,leftx:a0,lefty:a1,rightx:a2,righty:a3,"]'
                    '\n[fly]\njoy = "sdl:config"\nrumble = false\n')
    o = build_options(load_file(str(path))[0], {})
    assert o.joy == "sdl:config" and o.rumble is False and len(o.mappings) == 1
    sticks = open_sticks(o.joy, Clock(), mappings=SdlMappings(o.sdl_mapping, o.mappings))
    assert sticks.profile.name == "sdl-gamecontroller"  # a game controller now, through the config's mapping
    sticks.close()
    path.write_text('mappings = "not a list"\n[fly]\n')
    with pytest.raises(ConfigError, match="is not a list of SDL mapping lines"):
        build_options(load_file(str(path))[0], {})


def test_a_broken_sdl_mapping_on_the_command_line_is_one_sentence_and_exit_2(tmp_path: Path) -> None:
    from click.testing import CliRunner

    from joyfly.cli import main

    db = tmp_path / "db.txt"
    db.write_text("\n\nbroken\n")
    result = CliRunner().invoke(main, ["fly", "--joy", "sdl", "--sdl-mapping", str(db)])
    assert result.exit_code == 2
    assert result.output.strip() == (f"joyfly: {db} line 3 is not an SDL game-controller mapping (Couldn't parse GUID "
                                     "from broken): fix or remove that line (the format is GUID,name,a:b0,...,"
                                     "leftx:a0,... as in gamecontrollerdb.txt).")


def test_the_device_is_found_again_even_when_its_plug_event_was_pumped_away(pads: list[VirtualPad]) -> None:
    pads.append(VirtualPad.controller("Stolen Events", product=0x61))
    source = open_source("sdl:stolen", Clock()).source
    assert isinstance(source, SdlSource)
    try:
        pads[0].detach()
        assert not source.poll(0.0).connected
        pads[0].reattach()
        sdl_api().pump()  # someone else took the ADDED event
        assert source.poll(1.0).connected  # found by the rescan
    finally:
        source.close()


def test_a_closed_source_stays_closed(pads: list[VirtualPad]) -> None:
    pads.append(VirtualPad.controller("Closed Pad", product=0x62))
    source = open_source("sdl:closed", Clock()).source
    source.close()
    assert not source.poll(0.6).connected  # not reopened by the rescan
