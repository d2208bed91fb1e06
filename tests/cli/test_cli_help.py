"""The two command lines as a new user meets them (issue 10.11, 10.14): -h everywhere, --version, whole command
summaries, no "[default: None]", helps that explain their choices and the --speed relation, one error style."""

from __future__ import annotations

from collections.abc import Iterator
from importlib.metadata import version

import click
import pytest
from click.testing import CliRunner
from support import REPO_ROOT

import joyfly.cli
import joyfly.config
import sitl_emu.cli.main
import sitl_emu.cli.options
from joyfly.sticks.profiles.profile import read_config

REPO = REPO_ROOT
TOOLS = {"joyfly": joyfly.cli.main, "sitl-emu": sitl_emu.cli.main.main}


def command_paths(group: click.Command, path: tuple[str, ...] = ()) -> Iterator[tuple[str, ...]]:
    yield path
    if isinstance(group, click.Group):
        for name, sub in group.commands.items():
            yield from command_paths(sub, (*path, name))


ALL = [(tool, path) for tool, group in TOOLS.items() for path in command_paths(group)]


def invoke(tool: str, *args: str, width: int = 80) -> click.testing.Result:
    return CliRunner().invoke(TOOLS[tool], list(args), prog_name=tool, terminal_width=width)


@pytest.mark.parametrize(("tool", "path"), ALL, ids=[" ".join((t, *p)) for t, p in ALL])
def test_dash_h_is_help_everywhere_and_shows_no_none_default(tool: str, path: tuple[str, ...]) -> None:
    short, long = invoke(tool, *path, "-h"), invoke(tool, *path, "--help")
    assert short.exit_code == 0, short.output
    assert short.output == long.output
    assert short.output.startswith(f"Usage: {' '.join((tool, *path))} ")
    assert "default: None" not in short.output
    assert "-h, --help" in short.output


@pytest.mark.parametrize(("tool", "path"), [("joyfly", ()), ("joyfly", ("joystick",)), ("sitl-emu", ())])
def test_group_help_lists_whole_summaries(tool: str, path: tuple[str, ...]) -> None:
    for width in (80, 60):
        text = invoke(tool, *path, "--help", width=width).output
        commands = text.split("Commands:", 1)[1]
        assert "..." not in commands, commands


@pytest.mark.parametrize(("tool", "path"), ALL, ids=[" ".join((t, *p)) for t, p in ALL])
def test_version_on_every_command_comes_from_the_package_metadata(tool: str, path: tuple[str, ...]) -> None:
    result = invoke(tool, *path, "--version")
    assert result.exit_code == 0, result.output
    assert result.output == invoke(tool, "--version").output
    assert result.output.startswith(f"{tool} {version('joyfly')}")


def test_fly_help_says_what_the_control_choices_do_and_how_speed_relates() -> None:
    text = " ".join(invoke("joyfly", "fly", "--help").output.split())
    assert "(the seed)" not in text
    assert "velocity: the sticks set the vehicle's velocity" in text and "step: the setpoint is" in text
    assert "position: Position mode (POSCTL)" in text and "altitude: Altitude mode (ALTCTL)" in text
    assert "default: 20 (OFFBOARD), 25 (position, altitude: QGroundControl's)" in text
    assert "sitl-emu serve --speed N" in text
    serve = " ".join(invoke("sitl-emu", "serve", "--help").output.split())
    assert "joyfly fly --speed N" in serve


def test_both_tools_take_the_same_speed_range() -> None:
    for tool, path in (("joyfly", ("demo",)), ("sitl-emu", ("serve",))):
        group = TOOLS[tool]
        assert isinstance(group, click.Group)
        speed = next(p for p in group.commands[path[0]].params if p.name == "speed")
        assert isinstance(speed.type, click.FloatRange)
        assert (speed.type.min, speed.type.max) == (joyfly.config.SPEED_MIN, joyfly.config.SPEED_MAX)
    assert (joyfly.config.BOUNDS["speed"].lo, joyfly.config.BOUNDS["speed"].hi) == (
        joyfly.config.SPEED_MIN, joyfly.config.SPEED_MAX)


@pytest.mark.parametrize(("tool", "args"), [
    ("joyfly", ["--frobnicate"]),  # click: no such option (root)
    ("joyfly", ["fly", "--speed", "fast"]),  # click: bad type
    ("joyfly", ["fly", "--rate", "1"]),  # joyfly's own range check
    ("joyfly", ["fly", "--joy", "/no/such/js0"]),  # joystick
    ("joyfly", ["joystick", "test", "--duration", "-1"]),  # click range in a nested group
    ("joyfly", ["joystick", "test", "--joy", "/no/such/js0"]),  # ClickException in a nested group
    ("joyfly", ["nosuchcommand"]),
    ("sitl-emu", ["serve", "--home", "1,2"]),  # sitl-emu's own check
    ("sitl-emu", ["serve", "--port", "x"]),  # click: bad type
    ("sitl-emu", ["nosuchcommand"]),
])
def test_every_user_error_has_the_same_one_line_style(tool: str, args: list[str]) -> None:
    result = invoke(tool, *args)
    assert result.exit_code in (1, 2) and isinstance(result.exception, SystemExit)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"{tool}: "), result.stderr
    assert "Error:" not in result.output and "Usage:" not in result.output
    assert lines[0].endswith((".", "?", ")"))


def test_usage_errors_point_at_the_right_help() -> None:
    assert invoke("joyfly", "fly", "--speed", "fast").stderr.strip().endswith("(see 'joyfly fly --help').")
    assert "(see 'sitl-emu serve --help')" in invoke("sitl-emu", "serve", "--port", "x").stderr


def test_pyproject_uses_the_spdx_license_and_declares_pyserial() -> None:
    meta = read_config(str(REPO / "pyproject.toml"))
    assert meta["project"]["license"] == "BSD-3-Clause"  # a table is deprecated (setuptools >= 77 warns)
    assert any(r.replace(" ", "").startswith("setuptools>=77") for r in meta["build-system"]["requires"])
    assert any(d.startswith("pyserial") for d in meta["project"]["dependencies"])
    import serial  # the declared dependency is installed

    assert serial.Serial is not None

