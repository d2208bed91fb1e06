"""Virtual joysticks: the script format, timing on an injected clock, recording and replay."""

from __future__ import annotations

import io
import json
from pathlib import Path

import pytest
from support import REPO_ROOT

from joyfly.sticks.js.reader import JoystickError, open_joystick
from joyfly.sticks.mapping import StickMapper
from joyfly.sticks.profiles.profile import load_profile
from joyfly.sticks.virtual import JoyRecorder, ReplaySource, ScriptSource, parse_script, record_to
from joyfly.types import Action

EXAMPLE = REPO_ROOT / "examples" / "joystick_script.txt"


class FakeClock:
    def __init__(self, t_s: float = 50.0) -> None:
        self.t_s = t_s

    def now(self) -> float:
        return self.t_s

    def sleep(self, seconds: float) -> None:
        self.t_s += max(0.0, seconds)


SCRIPT = """
# comment line
0     forward=0.5 right=-1        # trailing comment
1.0   arm=1
+0.5  arm=0 up=1 yaw=-0.25
3     return=1
4     end
"""


def test_script_values_appear_at_their_times_and_end_disconnects():
    clock = FakeClock()
    src = ScriptSource.from_text(SCRIPT, clock)
    mapper = StickMapper(load_profile("auto", src.name, {}))
    cmd, _ = mapper.update(src.poll(0.0))
    assert (cmd.forward, cmd.right, cmd.up, cmd.yaw) == pytest.approx((0.5, -1.0, 0.0, 0.0), abs=1e-4)

    clock.sleep(1.0)
    cmd, _ = mapper.update(src.poll(0.0))
    assert cmd.pressed == {Action.ARM}

    clock.sleep(0.5)
    cmd, _ = mapper.update(src.poll(0.0))
    assert cmd.pressed == frozenset() and cmd.up == pytest.approx(1.0) and cmd.yaw == pytest.approx(-0.25, abs=1e-4)

    clock.sleep(1.5)
    cmd, actions = mapper.update(src.poll(0.0))
    assert actions == {Action.RETURN}  # 'return' is the alias of rtl

    clock.sleep(1.0)
    state = src.poll(0.0)
    assert state.connected is False
    assert mapper.update(state)[0].connected is False


def test_script_time_starts_at_first_poll_and_poll_waits_for_the_next_step():
    clock = FakeClock()
    src = ScriptSource.from_text("0 forward=0\n2 forward=1\n", clock)
    clock.sleep(30.0)  # the session took a while to connect: the script has not started yet
    assert src.poll(0.0).axes[0] == 0
    start = clock.now()
    state = src.poll(5.0)  # sleeps only until the next step, then returns it
    assert clock.now() - start == pytest.approx(2.0)
    assert state.axes[0] == 32767
    start = clock.now()
    src.poll(0.1)  # nothing more to come: waits the timeout, like a quiet device
    assert clock.now() - start == pytest.approx(0.1)


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        ("0 forward=2", "line 1: forward=2 is outside -1..1"),
        ("0 arm=1\nx arm=0", "line 2: 'x' is not a time"),
        ("2 arm=1\n1 arm=0", "goes back"),
        ("0 throttle=0.5", "unknown name 'throttle'"),
        ("0 land=0.5", "must be 1 or 0"),
        ("0 forward", "is not name=value"),
    ],
)
def test_script_mistakes_name_the_line(text, fragment):
    with pytest.raises(JoystickError) as info:
        parse_script(text, "my.txt")
    assert fragment in str(info.value) and str(info.value).startswith("my.txt line")


def test_example_script_leaves_the_take_off_to_joyfly_flies_a_square_pushes_the_fence_and_lands():
    """`joyfly fly` arms, takes off and enters OFFBOARD itself (joyfly/session/flight_session.py): the example
    presses only LAND, and keeps the sticks centred for the take-off's first 8 s."""
    clock = FakeClock(0.0)
    src = open_joystick(f"script:{EXAMPLE}", clock)
    mapper = StickMapper(load_profile("auto", src.name, {}))
    fired: list[Action] = []
    north_demand_s = 0.0
    first_stick_s: float | None = None
    while True:
        state = src.poll(0.0)
        cmd, actions = mapper.update(state)
        fired.extend(sorted(actions, key=lambda a: a.value))
        north_demand_s += 0.05 * cmd.forward if cmd.forward > 0.9 else 0.0
        if first_stick_s is None and any((cmd.forward, cmd.right, cmd.up, cmd.yaw)):
            first_stick_s = clock.now()
        if not state.connected:
            break
        clock.sleep(0.05)
    assert fired == [Action.LAND]
    assert first_stick_s == pytest.approx(8.0)
    assert north_demand_s > 3.5  # a long full-stick push north: 20 m of demand against a 5 m fence
    assert 40.0 < clock.now() < 60.0


def test_missing_script_file_is_one_sentence(tmp_path):
    with pytest.raises(JoystickError) as info:
        open_joystick(f"script:{tmp_path / 'nope.txt'}", FakeClock())
    assert str(info.value) == f"No script file at {tmp_path / 'nope.txt'}: check the path after 'script:'."


def test_record_then_replay_gives_the_same_states_at_the_same_times(tmp_path):
    clock = FakeClock(10.0)
    out = tmp_path / "session.jsonl"
    src = record_to(ScriptSource.from_text(SCRIPT, clock), str(out))
    seen = []
    for _ in range(100):
        state = src.poll(0.0)
        seen.append((round(clock.now() - 10.0, 3), state.axes, state.buttons, state.connected))
        if not state.connected:
            break
        clock.sleep(0.1)
    src.close()
    lines = [json.loads(ln) for ln in out.read_text().splitlines()]
    assert lines[0]["name"] == "joyfly script" and lines[-1]["end"] is True
    assert len(lines) == 2 + 5  # header, 5 distinct states (incl. the disconnect), end

    clock2 = FakeClock(500.0)
    replay = open_joystick(f"replay:{out}", clock2)
    assert isinstance(replay, ReplaySource) and replay.name == "joyfly script"
    replayed = []
    for _ in range(100):
        state = replay.poll(0.0)
        replayed.append((round(clock2.now() - 500.0, 3), state.axes, state.buttons, state.connected))
        if not state.connected:
            break
        clock2.sleep(0.1)
    assert replayed == seen


def test_recorder_writes_only_changes():
    buf = io.StringIO()
    rec = JoyRecorder(buf, "pad", "/dev/input/js0")
    from joyfly.types import JoyState

    rec.record(JoyState(1.0, (0, 0), (0,)))
    rec.record(JoyState(1.1, (0, 0), (0,)))
    rec.record(JoyState(1.2, (5, 0), (0,)))
    rec.close()
    lines = [json.loads(ln) for ln in buf.getvalue().splitlines()]
    assert [ln.get("t") for ln in lines] == [None, 0.0, pytest.approx(0.2), pytest.approx(0.2)]


def test_replay_of_a_non_recording_is_refused(tmp_path):
    bad = tmp_path / "x.jsonl"
    bad.write_text('{"hello": 1}\n')
    with pytest.raises(JoystickError) as info:
        ReplaySource.from_file(str(bad), FakeClock())
    assert "not a joyfly recording" in str(info.value)


def _recorded_session(tmp_path: Path) -> tuple[Path, list[tuple[float, tuple[int, ...], tuple[int, ...], bool]]]:
    clock = FakeClock(10.0)
    out = tmp_path / "session.jsonl"
    src = record_to(ScriptSource.from_text(SCRIPT, clock), str(out))
    seen = []
    while src.source.state().connected:
        state = src.poll(0.1)
        seen.append((round(clock.now() - 10.0, 3), state.axes, state.buttons, state.connected))
    src.close()
    return out, seen


def test_a_recording_header_says_what_the_file_is(tmp_path):
    out, _ = _recorded_session(tmp_path)
    header = json.loads(out.read_text().splitlines()[0])
    assert header["joyfly_recording"] == 1 and header["name"] == "joyfly script"
    assert "joyfly fly --joy" in header["about"]  # a reader of the file learns how to use it


def test_a_recording_given_as_a_plain_path_replays_like_replay(tmp_path):
    out, seen = _recorded_session(tmp_path)
    for spec in (str(out), f"replay:{out}"):
        clock = FakeClock(500.0)
        replay = open_joystick(spec, clock)
        assert isinstance(replay, ReplaySource) and replay.name == "joyfly script" and replay.path == str(out)
        replayed = []
        while replay.state().connected:
            state = replay.poll(0.1)
            replayed.append((round(clock.now() - 500.0, 3), state.axes, state.buttons, state.connected))
        assert replayed == seen


def test_record_to_an_unwritable_place_is_one_sentence(tmp_path):
    for bad in (tmp_path, tmp_path / "no-such-dir" / "rec.jsonl"):
        with pytest.raises(JoystickError) as info:
            record_to(ScriptSource.from_text(SCRIPT, FakeClock()), str(bad))
        text = str(info.value)
        assert text.startswith(f"Cannot write the recording {bad} (") and text.endswith(".") and "\n" not in text


def test_record_over_the_joystick_file_itself_is_refused(tmp_path):
    script = tmp_path / "s.txt"
    script.write_text(SCRIPT)
    source = open_joystick(f"script:{script}", FakeClock())
    with pytest.raises(JoystickError) as info:
        record_to(source, str(script))
    assert str(info.value) == (f"--record {script} would overwrite the joystick file it reads: "
                               "record to another file.")
    assert script.read_text() == SCRIPT


@pytest.mark.parametrize(("body", "fragment"), [
    ('{"t": "soon", "axes": [0], "buttons": []}', "line 2 is not a joystick record"),
    ('{"t": 0, "axes": ["up"], "buttons": []}', "line 2 is not a joystick record"),
    ('{"t": NaN, "axes": [0], "buttons": []}', "line 2 is not a joystick record"),
    ('[1, 2]', "line 2 is not a joystick record"),
    ('\n{"t": 0, "axes": [0]', "line 3 is not JSON"),
    ("[" * 5000, "line 2 is not JSON"),
])
def test_a_damaged_recording_names_its_line(tmp_path, body, fragment):
    rec = tmp_path / "rec.jsonl"
    rec.write_text('{"joyfly_recording": 1, "name": "pad"}\n' + body + "\n")
    for spec in (str(rec), f"replay:{rec}"):
        with pytest.raises(JoystickError) as info:
            open_joystick(spec, FakeClock())
        text = str(info.value)
        assert text.startswith(f"{rec} {fragment}") and text.endswith(": replay a file written by --record."), text


def test_a_script_that_is_not_text_is_one_sentence(tmp_path):
    script = tmp_path / "s.txt"
    script.write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(JoystickError) as info:
        open_joystick(f"script:{script}", FakeClock())
    assert str(info.value) == f"The script file {script} is not UTF-8 text: check the path after 'script:'."
