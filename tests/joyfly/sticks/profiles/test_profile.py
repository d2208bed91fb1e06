"""Profiles: matching by device name, choosing by name, TOML overrides, and the sticks-at-rest check."""

from __future__ import annotations

import pytest

from joyfly.sticks.profiles.profile import (
    ProfileError,
    get_profile,
    load_profile,
    match_profile,
    profile_names,
    read_config,
    rest_problems,
)
from joyfly.types import Action, JoyState


@pytest.mark.parametrize(
    ("device_name", "expected"),
    [
        ("Microsoft X-Box 360 pad", "xbox"),
        ("Microsoft X-Box One pad", "xbox"),
        ("Microsoft Xbox Series S|X Controller", "xbox"),
        ("Generic X-Box pad", "xbox"),
        ("Logitech Gamepad F310", "logitech-x"),
        ("Logitech Gamepad F710", "logitech-x"),
        ("Logitech Dual Action", "logitech-d"),
        ("Logicool Dual Action", "logitech-d"),
        ("Logitech Cordless RumblePad 2", "logitech-d"),
        ("Sony Interactive Entertainment Wireless Controller", "dualshock"),
        ("Wireless Controller", "dualshock"),
        ("Sony Interactive Entertainment DualSense Wireless Controller", "dualshock"),
        ("EdgeTX RadioMaster TX16S Joystick", "radio"),
        ("OpenTX FrSky Taranis Joystick", "radio"),
        ("joyfly script", "script"),
        ("Xbox 360 Controller (SDL game controller)", "sdl-gamecontroller"),
        ("PS4 Controller (SDL game controller)", "sdl-gamecontroller"),
        ("Thrustmaster T.16000M", "generic"),
        ("/tmp/some-fifo", "generic"),
    ],
)
def test_profile_is_matched_by_device_name(device_name, expected):
    assert match_profile(device_name, kernel_release="6.8.0-45-generic").name == expected


def test_no_builtin_profile_flies_a_trigger():
    triggers = {"xbox": {2, 5}, "logitech-x": {2, 5}, "dualshock": {2, 5}, "dualshock-old": {3, 4}}
    for name, trigger_axes in triggers.items():
        used = {a.index for a in get_profile(name).axes.values()}
        assert not used & trigger_axes, name


def test_name_beats_auto_and_aliases_work():
    assert load_profile("ps4", "Microsoft X-Box 360 pad", {}).name == "dualshock"
    assert load_profile("auto", "Microsoft X-Box 360 pad", {"base": "f310"}).name == "logitech-x"
    assert load_profile("xbox", "x", {"base": "f310"}).name == "xbox"  # --profile beats the config's base
    assert set(profile_names()) >= {"xbox", "dualshock", "dualshock-old", "logitech-d", "logitech-x", "radio"}


def test_unknown_profile_name_lists_the_choices():
    with pytest.raises(ProfileError) as info:
        load_profile("nintendo", "", {})
    assert str(info.value).startswith("Unknown profile 'nintendo': choose auto or one of script, sdl-gamecontroller, "
                                      "xbox,")


def test_config_table_merges_over_the_builtin(tmp_path):
    config = tmp_path / "joyfly.toml"
    config.write_text(
        """
[profile]
deadzone = 0.1
expo = 0.3
arm_hold_s = 0.5

[profile.forward]
index = 1
invert = true
scale = 0.5

[profile.yaw]
index = -1

[profile.buttons]
deadman = 4
land = -1
"""
    )
    profile = load_profile("auto", "Microsoft X-Box 360 pad", read_config(str(config)))
    forward = profile.axis("forward")
    assert (forward.index, forward.invert, forward.deadzone, forward.expo, forward.scale) == (1, True, 0.1, 0.3, 0.5)
    right = profile.axis("right")
    assert (right.index, right.deadzone, right.expo) == (3, 0.1, 0.3)  # untouched axis keeps its index
    assert profile.axis("yaw") is None
    assert profile.button(Action.DEADMAN) == 4 and profile.button(Action.LAND) is None
    assert profile.button(Action.ARM) == 7 and profile.arm_hold_s == 0.5


@pytest.mark.parametrize(
    ("table", "fragment"),
    [
        ({"dedzone": 0.1}, "Unknown key 'dedzone' in [profile]"),
        ({"forward": {"index": 1, "inverted": True}}, "Unknown key 'inverted' in [profile.forward]"),
        ({"forward": {"index": "four"}}, "profile.forward.index = 'four' is not an axis number"),
        ({"deadzone": 2}, "profile.deadzone = 2 is not a number in 0..0.9"),
        ({"buttons": {"fire": 1}}, "Unknown button action 'fire'"),
        ({"forward": 3}, "profile.forward must be a table"),
        ({"throttle_abs": {"invert": True}}, "[profile.throttle_abs] maps no axis yet"),
        ({"buttons": 5}, "profile.buttons must be a table"),
    ],
)
def test_config_mistakes_are_one_sentence(table, fragment):
    with pytest.raises(ProfileError) as info:
        load_profile("xbox", "", table)
    assert fragment in str(info.value)
    assert "\n" not in str(info.value)


def test_whole_config_dict_is_accepted_too():
    profile = load_profile("auto", "Microsoft X-Box 360 pad", {"profile": {"buttons": {"deadman": 5}}, "fly": {}})
    assert profile.button(Action.DEADMAN) == 5


def test_bad_toml_is_reported(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[profile\n")
    with pytest.raises(ProfileError) as info:
        read_config(str(bad))
    assert "is not valid TOML" in str(info.value)
    with pytest.raises(ProfileError):
        read_config(str(tmp_path / "none.toml"))
    binary = tmp_path / "binary.toml"
    binary.write_bytes(bytes(range(256)))
    with pytest.raises(ProfileError) as info:
        read_config(str(binary))
    assert "is not a text file" in str(info.value)


def test_rest_check_flags_a_stick_role_on_a_trigger():
    # An old hid-sony DS4 read with the modern profile: axes 3 (right) and 4 (forward) are L2/R2 resting at -32767.
    state = JoyState(0.0, (0, 0, 0, -32767, -32767, 0, 0, 0), (0,) * 13)
    problems = rest_problems(get_profile("dualshock"), state)
    assert len(problems) == 2 and problems[0].startswith("Axis 4 (forward) reads -100% with the sticks untouched")
    assert problems[1].startswith("Axis 3 (right) reads -100%")
    assert rest_problems(get_profile("dualshock-old"), state) == []


def test_config_can_add_an_axis_the_profile_lacks():
    profile = load_profile("radio", "", {"deadzone": 0.1, "expo": 0.2, "up": {"index": 5, "invert": True}})
    up = profile.axis("up")
    assert (up.index, up.invert, up.deadzone, up.expo) == (5, True, 0.1, 0.2)
    assert profile.axis("throttle_abs").expo == 0.0  # expo only shapes centred sticks
