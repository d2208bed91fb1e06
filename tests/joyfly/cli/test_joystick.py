"""`joyfly joystick list` and `joyfly joystick test`, through click's runner."""

from __future__ import annotations

import io
import os
import threading

from click.testing import CliRunner
from support import REPO_ROOT

from joyfly.cli.joystick import LiveView, joystick
from joyfly.sticks.js.reader import JS_EVENT_AXIS, JS_EVENT_BUTTON, JS_EVENT_INIT, pack_event
from joyfly.sticks.profiles.profile import get_profile
from joyfly.types import JoyState, StickCommand

SCRIPT = "0 forward=0.5\n0.05 arm=1\n+0.1 arm=0\n+0.05 end\n"


EXAMPLE = os.path.join(REPO_ROOT, "examples", "joystick_script.txt")


def run(*args: str):
    return CliRunner().invoke(joystick, list(args))


def test_list_shows_each_node_with_its_profile(tmp_path):
    os.mkfifo(tmp_path / "js0")
    os.mkfifo(tmp_path / "js1")
    result = run("list", "--dev-dir", str(tmp_path))
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    assert len(lines) == 2
    assert lines[0].startswith(f"{tmp_path / 'js0'}  ") and lines[0].endswith("profile: generic")


def test_list_without_joysticks_says_what_to_do(tmp_path):
    result = run("list", "--dev-dir", str(tmp_path))
    assert result.exit_code == 0  # an answer, not a failure
    assert result.output.endswith(f"No joystick found (SDL sees none, and no {tmp_path}/js*): plug one in, or fly a "
                                  f"virtual one with --joy script:{EXAMPLE}.\n"), result.output


def test_the_no_joystick_hints_name_a_script_that_exists_from_any_folder(tmp_path, monkeypatch):
    """The hints said `--joy script:examples/joystick_script.txt`, a path only the clone's root has: from any other
    folder the suggested command failed with "No script file at examples/joystick_script.txt"."""
    from joyfly.cli.main import main

    monkeypatch.chdir(tmp_path)
    missing = str(tmp_path / "js9")
    fly = CliRunner().invoke(main, ["fly", "--joy", missing])
    assert fly.exit_code == 2 and fly.output.rstrip().endswith(f"--joy script:{EXAMPLE}."), fly.output
    listed = run("list", "--dev-dir", str(tmp_path))
    for output in (fly.output, listed.output):
        hinted = output.rsplit("--joy script:", 1)[1].rstrip().rstrip(".")
        assert os.path.isabs(hinted) and os.path.isfile(hinted), output
    test = run("test", "--joy", "script:examples/joystick_script.txt", "--duration", "0.1")
    assert test.exit_code == 1 and test.output == (
        f"joyfly: No script file at examples/joystick_script.txt in this folder: joyfly's example is {EXAMPLE}.\n")


def test_test_prints_plain_lines_and_stops_at_the_script_end(tmp_path):
    script = tmp_path / "s.txt"
    script.write_text(SCRIPT)
    result = run("test", "--joy", f"script:{script}")
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    assert lines[0] == f"joyfly script ({script}), profile script"
    assert "forward=+0.50" in lines[1] and "pressed=-" in lines[1]
    assert any("pressed=arm(" in ln for ln in lines)
    assert lines[-1].endswith("disconnected (the virtual joystick reached its end)")


def test_test_reads_a_fifo_until_the_duration(tmp_path):
    fifo = tmp_path / "js-fifo"
    os.mkfifo(fifo)

    def writer() -> None:
        fd = os.open(fifo, os.O_WRONLY)  # blocks until the command opens the reader
        os.write(fd, pack_event(JS_EVENT_AXIS | JS_EVENT_INIT, 0, 0) + pack_event(JS_EVENT_AXIS | JS_EVENT_INIT, 1, 0))
        os.write(fd, pack_event(JS_EVENT_AXIS, 1, -32767) + pack_event(JS_EVENT_BUTTON, 0, 1))
        os.close(fd)

    thread = threading.Thread(target=writer, daemon=True)
    thread.start()
    result = run("test", "--joy", str(fifo), "--duration", "0.4")
    thread.join(timeout=2)
    assert result.exit_code == 0, result.output
    assert "axes=[0, -32767] buttons=[1] forward=+1.00" in result.output  # generic profile: axis 1 up = forward
    assert "disconnected" in result.output and "vanished" in result.output


def test_record_then_replay_shows_the_same_session(tmp_path):
    script = tmp_path / "s.txt"
    script.write_text(SCRIPT)
    rec = tmp_path / "rec.jsonl"
    first = run("test", "--joy", f"script:{script}", "--record", str(rec))
    again = run("test", "--joy", f"replay:{rec}")
    assert first.exit_code == 0 and again.exit_code == 0, again.output

    def body(output: str) -> list[str]:  # drop the header and the timing column
        return [ln.split(" ", 1)[1] for ln in output.splitlines()[1:]]

    assert body(again.output) == body(first.output)


def test_errors_are_one_sentence(tmp_path):
    result = run("test", "--joy", str(tmp_path / "js7"), "--dev-dir", str(tmp_path))
    assert result.exit_code == 1
    assert result.output.startswith(f"joyfly: No joystick at {tmp_path / 'js7'}, and none is connected")
    assert "Traceback" not in result.output
    script = tmp_path / "s.txt"
    script.write_text(SCRIPT)
    result = run("test", "--joy", f"script:{script}", "--profile", "wii")
    assert result.exit_code == 1 and "Unknown profile 'wii'" in result.output


def test_test_applies_the_config_profile_table(tmp_path):
    script = tmp_path / "s.txt"
    script.write_text(SCRIPT)
    config = tmp_path / "joyfly.toml"
    config.write_text("[profile.forward]\nscale = 0.5\n")
    result = run("test", "--joy", f"script:{script}", "--config", str(config))
    assert result.exit_code == 0, result.output
    assert "profile script+config" in result.output and "forward=+0.25" in result.output


def test_live_view_redraws_in_place():
    out = io.StringIO()
    view = LiveView(out)
    state = JoyState(1.0, (0, -32767), (0, 1))
    view.show(state, StickCommand(forward=1.0, time_s=1.0), 0.0, "")
    view.show(JoyState(1.1, (0, 0), (0, 0)), StickCommand(time_s=1.1), 0.0, "")
    text = out.getvalue()
    assert "axes     0:+0.00 1:-1.00" in text and "forward=+1.00" in text
    assert "MANUAL_CONTROL x +1000 y    +0 z  500 r    +0" in text  # what --control position would send
    assert "\x1b[6F" in text  # the second frame moved the cursor back over the first
    assert get_profile("xbox").name == "xbox"


def test_profiles_lists_every_builtin_layout():
    result = run("profiles")
    assert result.exit_code == 0
    xbox = result.output.split("xbox: ", 1)[1].splitlines()
    assert "forward=4 inverted, right=3, up=1 inverted, yaw=0" in xbox[2] and "arm=7" in xbox[2]
    assert "radio: " in result.output and "generic: " in result.output


def test_test_reads_a_raw_file_and_refuses_a_plain_one(tmp_path):
    events = tmp_path / "events.bin"
    init = pack_event(JS_EVENT_AXIS | JS_EVENT_INIT, 0, 0) + pack_event(JS_EVENT_AXIS | JS_EVENT_INIT, 1, 0)
    events.write_bytes(init + pack_event(JS_EVENT_AXIS, 1, -32767, 100) + pack_event(JS_EVENT_AXIS, 1, 0, 400))
    result = run("test", "--joy", f"raw:{events}", "--duration", "0.2")
    assert result.exit_code == 0, result.output
    assert "axes=[0, -32767]" in result.output
    result = run("test", "--joy", str(events), "--duration", "0.2")
    assert result.exit_code == 1 and len(result.output.splitlines()) == 1
    assert result.output.startswith(f"joyfly: {events} is a regular file") and f"raw:{events}" in result.output


def test_an_unknown_profile_is_named_before_any_joystick_is_looked_for(tmp_path):
    """With no joystick, `--profile nosuch` said "No joystick ..." and never named the option's mistake."""
    from joyfly.cli.main import main

    missing = str(tmp_path / "js9")
    fly = CliRunner().invoke(main, ["fly", "--joy", missing, "--profile", "nosuch"])
    assert fly.exit_code == 2 and "Unknown profile 'nosuch'" in fly.output and "No joystick" not in fly.output
    test = run("test", "--joy", missing, "--dev-dir", str(tmp_path), "--profile", "nosuch")
    assert test.exit_code == 1 and "Unknown profile 'nosuch'" in test.output and "No joystick" not in test.output
    config = tmp_path / "joyfly.toml"
    config.write_text("[profile]\nbase = \"nosuch\"\n")
    fly = CliRunner().invoke(main, ["fly", "--joy", missing, "--config", str(config)])
    assert fly.exit_code == 2 and "Unknown profile 'nosuch'" in fly.output and "No joystick" not in fly.output


def test_without_the_clone_the_hint_says_where_the_example_lives(tmp_path, monkeypatch):
    """Installed without the source tree (a wheel has no examples/), the hint says where the example is instead."""
    from joyfly.sticks import examples

    monkeypatch.setattr(examples, "EXAMPLES_DIR", tmp_path / "examples")
    assert examples.virtual_joystick_hint() == (
        "--joy script:FILE (such as examples/joystick_script.txt in joyfly's source repository)")
    assert examples.missing_example("examples/joystick_script.txt") is None
