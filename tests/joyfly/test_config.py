"""`joyfly fly` options: defaults, the TOML config file, command line over file, clear errors."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from joyfly.config import ConfigError, FlyOptions, build_options, load_file


def test_defaults_are_the_documented_ones() -> None:
    o = build_options({}, {})
    assert (o.joy, o.url, o.profile, o.control) == ("auto", "udp://:14540@127.0.0.1:14557", "auto",
                                                   "velocity")
    assert (o.step, o.alt, o.max_climb, o.max_speed, o.fence, o.rate, o.on_exit, o.joy_timeout) == (
        2.0, 3.0, 1.0, 5.0, 5.0, 20.0, "land", 5.0)


def test_config_file_sets_options_and_profile_and_the_command_line_wins(tmp_path: Path) -> None:
    path = tmp_path / "joyfly.toml"
    path.write_text('[fly]\nmax-speed = 3\nfence = 8.0\non_exit = "rtl"\ncontrol = "step"\n\n'
                    '[profile]\nbase = "xbox"\ndeadzone = 0.1\n')
    file_options, profile = load_file(str(path))
    o = build_options(file_options, {"fence": 2.5, "rate": None})
    assert (o.max_speed, o.fence, o.on_exit, o.control, o.rate) == (3.0, 2.5, "rtl", "step", 20.0)
    assert profile == {"base": "xbox", "deadzone": 0.1}
    settings = o.session_settings()
    assert settings.limits.control == "step" and settings.limits.max_speed_m_s == 3.0
    assert settings.limits.max_yaw_rate_rad_s == pytest.approx(math.radians(45.0))


def test_top_level_keys_work_without_a_fly_table(tmp_path: Path) -> None:
    path = tmp_path / "joyfly.toml"
    path.write_text('alt = 4.5\njoy = "script:demo.txt"\n')
    o = build_options(load_file(str(path))[0], {})
    assert (o.alt, o.joy) == (4.5, "script:demo.txt")


@pytest.mark.parametrize(("options", "fragment"), [
    ({"rate": 5.0}, "--rate 5 is out of range: use 10 to 200 Hz (PX4 leaves OFFBOARD after 1 s"),
    ({"on_exit": "crash"}, "--on-exit crash is not a choice here: use one of land, hold, rtl."),
    ({"control": "rate"}, "--control rate is not a choice here: use one of velocity, step, position, altitude."),
    ({"min_alt": 5.0, "max_alt": 4.0}, "--min-alt 5 must be below --max-alt (4 m)"),
    ({"alt": 20.0}, "--alt 20 is out of range: use 0.5 to 10 m (from --min-alt to --max-alt)"),
    ({"alt": -3.0}, "--alt -3 is out of range: use 0.5 to 10 m (from --min-alt to --max-alt)"),  # one range only
    ({"alt": 2000.0}, "--alt 2000 is out of range: use 0.5 to 10 m (from --min-alt to --max-alt)"),
    ({"max_alt": 2.0}, "the default --alt 3 is out of range: use 0.5 to 2 m"),
    ({"fence": -1.0}, "--fence -1 is out of range: use 0 to 10000 m (0 turns the fence off)."),
    ({"max_speed": "fast"}, "--max-speed fast is not a number: write a number from 0.1 to 20 m/s"),
    ({"max_speed": math.nan}, "--max-speed nan is not a number"),
    ({"rate": math.inf}, "--rate inf is not a number"),
    ({"step": 0.0}, "--step 0 is out of range: use 0.1 to 50 m."),
    ({"max_climb": 9.0}, "--max-climb 9 is out of range: use 0.1 to 8 m/s"),
    ({"max_yaw_rate": -1.0}, "--max-yaw-rate -1 is out of range: use 0 to 400 deg/s"),
    ({"joy_timeout": 0.0}, "--joy-timeout 0 is out of range: use 0.1 to 600 s."),
    ({"connect_timeout": 1e6}, "--connect-timeout 1e+06 is out of range: use 1 to 3600 s."),
    ({"speed": 0.01}, "--speed 0.01 is out of range: use 0.1 to 100 times real time"),
    ({"speed": 1000.0}, "--speed 1000 is out of range: use 0.1 to 100 times real time"),
    ({"min_alt": -1.0}, "--min-alt -1 is out of range: use 0 to 1000 m."),
    ({"url": "udp://:99999@127.0.0.1:14557"}, "--url udp://:99999@127.0.0.1:14557: the listen port 99999 is out of "
                                              "range; use 0 to 65535 (0: any free port)."),
])
def test_bad_options_end_in_one_sentence(options: dict[str, object], fragment: str) -> None:
    with pytest.raises(ConfigError) as err:
        build_options({}, options)
    assert fragment in str(err.value)
    assert str(err.value).count(". ") == 0 and str(err.value).endswith(".")


@pytest.mark.parametrize(("toml", "message"), [
    ('alt = "high"', 'alt = "high" is not a number: write a number between min-alt and max-alt (0.5 and 10 m '
                     'unless you change them), for example alt = 3.'),
    ("[fly]\nmax-speed = 50", "max-speed = 50 is out of range: use 0.1 to 20 m/s"),
    ("speed = nan", "speed = nan is not a number: write a number from 0.1 to 100 times real time, for example "
                    "speed = 1."),
    ("max-alt = 2.0", "the default --alt 3 is out of range: use 0.5 to 2 m (from --min-alt to max-alt)"),
    ("record = 5", 'record = 5 is not text: write it in quotes, for example record = "FILE".'),
    ("control = 1", 'control = 1 is not text: write it in quotes, for example control = "velocity".'),
    ('on-exit = "crash"', 'on-exit = "crash" is not a choice here: use one of land, hold, rtl.'),
    ('url = "udpin:0.0.0.0:70000"', 'url = "udpin:0.0.0.0:70000": the listen port 70000 is out of range; use 0 '
                                    "to 65535 (0: any free port)."),
    ("rate = true", "rate = true is not a number"),
])
def test_bad_values_in_the_config_file_name_the_file_the_key_and_the_fix(tmp_path: Path, toml: str,
                                                                          message: str) -> None:
    path = tmp_path / "joyfly.toml"
    path.write_text(toml + "\n")
    with pytest.raises(ConfigError) as err:
        build_options(load_file(str(path))[0], {}, source=str(path))
    text = str(err.value)
    assert message in text
    if not message.startswith("the default"):
        assert text.startswith(f"{path}: ")


def test_the_command_line_value_is_named_when_it_overrides_the_file(tmp_path: Path) -> None:
    path = tmp_path / "joyfly.toml"
    path.write_text("alt = 4.0\n")
    with pytest.raises(ConfigError, match=r"^--alt 40 is out of range"):
        build_options(load_file(str(path))[0], {"alt": 40.0}, source=str(path))


def test_unknown_config_key_is_named(tmp_path: Path) -> None:
    path = tmp_path / "joyfly.toml"
    path.write_text("[fly]\nmax-sped = 3\n")
    with pytest.raises(ConfigError, match="unknown option 'max-sped'"):
        load_file(str(path))


def test_every_option_has_a_default() -> None:
    assert FlyOptions().speed == 1.0 and FlyOptions().record is None


def test_position_and_altitude_control_stream_at_qgcs_25_hz_unless_told() -> None:
    assert build_options({}, {"control": "position"}).rate == 25.0
    assert build_options({"control": "altitude"}, {}).rate == 25.0
    assert build_options({}, {"control": "position", "rate": 40.0}).rate == 40.0
    assert build_options({"rate": 15}, {"control": "altitude"}).rate == 15.0
    assert build_options({}, {"control": "step"}).rate == 20.0
    assert build_options({}, {"control": "position"}).session_settings().limits.control == "position"


def test_position_control_refuses_a_profile_without_a_throttle() -> None:
    from joyfly.cli.main import throttle_problem
    from joyfly.sticks.profiles.profile import load_profile

    problem = throttle_problem("position", load_profile("generic", "some pad"))
    assert problem is not None and "maps no throttle" in problem and "[profile.up] index" in problem
    assert throttle_problem("position", load_profile("xbox", "x")) is None
    assert throttle_problem("altitude", load_profile("radio", "x")) is None  # a radio's throttle_abs
    assert throttle_problem("velocity", load_profile("generic", "some pad")) is None
