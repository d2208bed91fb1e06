"""`joyfly fly` options: defaults, the TOML config file, command line over file, clear errors."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from joyfly.config import ConfigError, FlyOptions, build_options, load_file


def test_defaults_are_the_documented_ones() -> None:
    o = build_options({}, {})
    assert (o.joy, o.url, o.profile, o.control) == ("/dev/input/js0", "udp://:14540@127.0.0.1:14557", "auto",
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
    ({"rate": 5.0}, "--rate must be at least 10 Hz"),
    ({"on_exit": "crash"}, "--on-exit must be one of"),
    ({"control": "rate"}, "--control must be one of"),
    ({"min_alt": 5.0, "max_alt": 4.0}, "--min-alt (5) must be below --max-alt (4)"),
    ({"alt": 20.0}, "--alt 20 m must lie between"),
    ({"fence": -1.0}, "--fence must be 0 (off)"),
    ({"max_speed": "fast"}, "must be a number"),
])
def test_bad_options_end_in_one_sentence(options: dict[str, object], fragment: str) -> None:
    with pytest.raises(ConfigError, match=fragment.replace("(", r"\(").replace(")", r"\)")):
        build_options({}, options)


def test_unknown_config_key_is_named(tmp_path: Path) -> None:
    path = tmp_path / "joyfly.toml"
    path.write_text("[fly]\nmax-sped = 3\n")
    with pytest.raises(ConfigError, match="unknown option 'max-sped'"):
        load_file(str(path))


def test_every_option_has_a_default() -> None:
    assert FlyOptions().speed == 1.0 and FlyOptions().record is None
