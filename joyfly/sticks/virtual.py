"""Virtual joysticks: `script:FILE` (timed stick and button values) and `replay:FILE` (a recorded session).

Script format (one step a line; `#` starts a comment; blank lines are ignored)::

    <time> <name>=<value> [<name>=<value> ...] [end]

- `<time>`: seconds since the first poll() of the source (absolute, non-decreasing), or `+<seconds>` after the
  previous line's time.
- sticks, already in the flying convention (no profile signs, deadzone or expo apply): `forward` (+1 = fly north),
  `right` (+1 = fly east), `up` (+1 = climb, a centred throttle stick), `yaw` (+1 = turn clockwise), each -1..1.
- buttons, 1 (down) or 0 (up): `land`, `rtl` (alias `return`), `hold`, `offboard`, `takeoff`, `arm` (held 1 s),
  `deadman` (only acts when the profile configures a deadman button). `joyfly fly` arms, takes off and enters
  OFFBOARD by itself; `offboard`, `takeoff` and `arm` fly again after a hold, a return or a landing (`arm` held on
  the ground while armed disarms).
- `end`: the virtual joystick goes away (JoyState.connected False from then on, as if unplugged).
Values hold until changed. A button press must last longer than the caller's poll period to be seen (0.2 s is safe).

    # joyfly fly takes off by itself meanwhile; then 2 m/s north for 3 s (5 m/s at full stick), land
    8     forward=0.4
    +3    forward=0
    +2    land=1
    +0.3  land=0
    +12   end

A script source reports the name "joyfly script", which selects the built-in `script` profile: axes 0..3 = forward,
right, up, yaw (scaled to +-32767 with the flying signs) and buttons 0..6 = arm, takeoff, land, rtl, hold, offboard,
deadman.

Recordings (`JoyRecorder`, `--record FILE`) are JSON lines: a header `{"joyfly_recording": 1, "about", "name",
"path"}` that says what the file is, then one `{"t", "axes", "buttons", "connected"}` line per change of the raw
JoyState (t in seconds since the first record), and `{"t", "end": true}` on close. `replay:FILE`, or the file's
path alone (`is_recording` knows it by its header), plays them back with their timing on the injected clock, under
the recorded device name (so the same profile matches), and reports connected False after the end.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import IO

from joyfly.sticks.examples import missing_example
from joyfly.sticks.js.events import AXIS_MAX, JoystickError
from joyfly.types import Clock, JoyState, JoystickSource

SCRIPT_NAME = "joyfly script"
SCRIPT_AXES = ("forward", "right", "up", "yaw")
SCRIPT_BUTTONS = ("arm", "takeoff", "land", "rtl", "hold", "offboard", "deadman")
_BUTTON_ALIASES = {"return": "rtl"}


@dataclass(frozen=True, slots=True)
class Step:
    """The full raw state from time t_s on (seconds since the source started)."""

    t_s: float
    axes: tuple[int, ...]
    buttons: tuple[int, ...]
    connected: bool = True


class TimedSource:
    """Plays a list of Steps on the injected clock; time 0 is the first poll(). Connected False after the last step
    when that step says so (a script's `end`, a recording's end)."""

    def __init__(self, name: str, path: str, steps: list[Step], clock: Clock) -> None:
        self.name = name
        self.path = path
        self.clock = clock
        self._steps = steps
        self._next = 0
        self._t0: float | None = None
        self._current = JoyState(time_s=clock.now(), axes=(), buttons=(), connected=True)

    @property
    def steps(self) -> tuple[Step, ...]:
        """Everything it will play, in order."""
        return tuple(self._steps)

    @property
    def ended(self) -> bool:
        return self._next >= len(self._steps) and not self._current.connected

    def poll(self, timeout_s: float) -> JoyState:
        if self._t0 is None:
            self._t0 = self.clock.now()
        if not self._apply_due():
            wait = max(0.0, timeout_s)
            if self._next < len(self._steps):
                wait = min(wait, max(0.0, self._steps[self._next].t_s - self._elapsed()))
            self.clock.sleep(wait)
            self._apply_due()
        return self.state()

    def state(self) -> JoyState:
        cur = self._current
        return JoyState(time_s=self.clock.now(), axes=cur.axes, buttons=cur.buttons, connected=cur.connected)

    def close(self) -> None:
        self._next = len(self._steps)
        self._current = JoyState(self.clock.now(), self._current.axes, self._current.buttons, connected=False)

    def _elapsed(self) -> float:
        return self.clock.now() - (self._t0 if self._t0 is not None else self.clock.now())

    def _apply_due(self) -> bool:
        applied = False
        elapsed = self._elapsed() + 1e-9
        while self._next < len(self._steps) and self._steps[self._next].t_s <= elapsed:
            step = self._steps[self._next]
            self._current = JoyState(self.clock.now(), step.axes, step.buttons, step.connected)
            self._next += 1
            applied = True
        return applied


# ---------------------------------------------------------------------------------------------------------- script


def _script_error(where: str, what: str) -> JoystickError:
    names = ", ".join((*SCRIPT_AXES, *SCRIPT_BUTTONS))
    return JoystickError(f"{where}: {what}; a script line is `<seconds> name=value ... [end]` with names {names}.")


def _parse_time(token: str, prev_t: float, where: str) -> float:
    try:
        t = prev_t + float(token[1:]) if token.startswith("+") else float(token)
    except ValueError:
        raise _script_error(where, f"'{token}' is not a time in seconds") from None
    if t < prev_t:
        raise _script_error(where, f"time {t:g} s goes back before {prev_t:g} s")
    return t


def _parse_assignment(token: str, axes: list[int], buttons: list[int], where: str) -> None:
    name, sep, text = token.partition("=")
    name = _BUTTON_ALIASES.get(name.lower(), name.lower())
    try:
        value = float(text)
    except ValueError:
        raise _script_error(where, f"'{token}' is not name=value") from None
    if not sep or (name not in SCRIPT_AXES and name not in SCRIPT_BUTTONS):
        raise _script_error(where, f"unknown name '{name}'")
    if name in SCRIPT_AXES:
        if not -1.0 <= value <= 1.0:
            raise _script_error(where, f"{name}={text} is outside -1..1")
        axes[SCRIPT_AXES.index(name)] = round(value * AXIS_MAX)
    else:
        if value not in (0.0, 1.0):
            raise _script_error(where, f"button {name}={text} must be 1 or 0")
        buttons[SCRIPT_BUTTONS.index(name)] = int(value)


def parse_script(text: str, source: str = "script") -> list[Step]:
    """Script text -> Steps (full states). Raises JoystickError naming the file and line of the first mistake."""
    axes, buttons = [0] * len(SCRIPT_AXES), [0] * len(SCRIPT_BUTTONS)
    steps: list[Step] = []
    t = 0.0
    for lineno, raw in enumerate(text.splitlines(), start=1):
        tokens = raw.split("#", 1)[0].split()
        if not tokens:
            continue
        where = f"{source} line {lineno}"
        t = _parse_time(tokens[0], t, where)
        ended = False
        for token in tokens[1:]:
            if token.lower() == "end":
                ended = True
            else:
                _parse_assignment(token, axes, buttons, where)
        steps.append(Step(t, tuple(axes), tuple(buttons), connected=not ended))
        if ended:
            break
    return steps


class ScriptSource(TimedSource):
    """`script:FILE`: a virtual joystick playing a timed script (format in the module docstring)."""

    @classmethod
    def from_text(cls, text: str, clock: Clock, path: str = "<script>") -> ScriptSource:
        return cls(SCRIPT_NAME, path, parse_script(text, path), clock)

    @classmethod
    def from_file(cls, path: str, clock: Clock) -> ScriptSource:
        return cls.from_text(_read_text(path, "script"), clock, path)

    def poll(self, timeout_s: float) -> JoyState:
        if self._t0 is None:
            # Until the first step, sticks are centred and buttons up.
            self._current = JoyState(self.clock.now(), (0,) * len(SCRIPT_AXES), (0,) * len(SCRIPT_BUTTONS))
        return super().poll(timeout_s)


def _read_text(path: str, what: str) -> str:
    try:
        return Path(path).read_text(encoding="utf-8")
    except FileNotFoundError:
        example = missing_example(path)
        if example is not None:
            raise JoystickError(f"No {what} file at {path} in this folder: joyfly's example is {example}.") from None
        raise JoystickError(f"No {what} file at {path}: check the path after '{what}:'.") from None
    except OSError as exc:
        raise JoystickError(f"Cannot read the {what} file {path} ({exc.strerror}): check the path.") from None
    except UnicodeDecodeError:
        raise JoystickError(f"The {what} file {path} is not UTF-8 text: check the path after '{what}:'.") from None


# ---------------------------------------------------------------------------------------------------------- record

RECORDING_KEY = "joyfly_recording"  # the header's first key, version 1
RECORDING_ABOUT = "a joystick session recorded by joyfly --record: replay it with joyfly fly --joy FILE"
HEADER_PEEK_BYTES = 4096


def is_recording(path: str) -> bool:
    """True when path is a regular file whose first line is a joyfly recording header (never reads a FIFO)."""
    if not os.path.isfile(path):
        return False
    try:
        with open(path, "rb") as fh:
            first = fh.read(HEADER_PEEK_BYTES).split(b"\n", 1)[0]
        header = json.loads(first)
    except (OSError, ValueError, RecursionError):  # unreadable, not JSON: the caller's own checks say what it is
        return False
    return isinstance(header, dict) and header.get(RECORDING_KEY) == 1


def _open_for_writing(path: str) -> IO[str]:
    try:
        return open(path, "w", encoding="utf-8")  # JoyRecorder.close() closes it
    except OSError as exc:
        raise JoystickError(f"Cannot write the recording {path} ({exc.strerror}): pass --record a file path in a "
                            "directory you can write to.") from None


class JoyRecorder:
    """Writes raw JoyStates as JSON lines, one line per change (see the module docstring)."""

    def __init__(self, out: str | IO[str], name: str, path: str) -> None:
        self._own = isinstance(out, str)
        self._out: IO[str] = _open_for_writing(out) if isinstance(out, str) else out
        self._t0: float | None = None
        self._last: tuple[tuple[int, ...], tuple[int, ...], bool] | None = None
        self._last_t = 0.0
        self._write({RECORDING_KEY: 1, "about": RECORDING_ABOUT, "name": name, "path": path})

    def record(self, state: JoyState) -> None:
        if self._t0 is None:
            self._t0 = state.time_s
        self._last_t = state.time_s - self._t0
        key = (state.axes, state.buttons, state.connected)
        if key == self._last:
            return
        self._last = key
        self._write({"t": round(self._last_t, 6), "axes": list(state.axes), "buttons": list(state.buttons),
                     "connected": state.connected})

    def close(self) -> None:
        if self._out.closed:
            return
        self._write({"t": round(self._last_t, 6), "end": True})
        if self._own:
            self._out.close()
        else:
            self._out.flush()

    def _write(self, obj: dict[str, object]) -> None:
        self._out.write(json.dumps(obj, separators=(",", ":")) + "\n")


class RecordingSource:
    """Wraps a source and records every state it returns."""

    def __init__(self, source: JoystickSource, recorder: JoyRecorder) -> None:
        self.source = source
        self.recorder = recorder
        self.name = source.name
        self.path = source.path

    def poll(self, timeout_s: float) -> JoyState:
        state = self.source.poll(timeout_s)
        self.recorder.record(state)
        return state

    def close(self) -> None:
        self.recorder.close()
        self.source.close()


def record_to(source: JoystickSource, out: str | IO[str]) -> RecordingSource:
    """`--record FILE`: the same source, also writing every change to out (never over the file the source reads)."""
    if isinstance(out, str) and _same_file(out, source.path):
        raise JoystickError(f"--record {out} would overwrite the joystick file it reads: record to another file.")
    return RecordingSource(source, JoyRecorder(out, source.name, source.path))


def _same_file(a: str, b: str) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:  # either does not exist (yet)
        return False


# ---------------------------------------------------------------------------------------------------------- replay


def parse_recording(text: str, source: str = "recording") -> tuple[str, list[Step]]:
    """Recording text -> (recorded device name, Steps); the last step is connected False (the end).
    Raises JoystickError naming the file and line of the first thing that is not a recording."""
    lines = _json_lines(text, source)
    header = lines[0][1] if lines else None
    if not isinstance(header, dict) or header.get(RECORDING_KEY) != 1:
        raise JoystickError(f"{source} is not a joyfly recording: replay a file written by --record.")
    steps, last, end_t = [], Step(0.0, (), ()), None
    for lineno, rec in lines[1:]:
        last_or_end = _record_step(rec, f"{source} line {lineno}")
        if isinstance(last_or_end, float):
            end_t = last_or_end
            break
        last = last_or_end
        steps.append(last)
    steps.append(Step(last.t_s if end_t is None else end_t, last.axes, last.buttons, connected=False))
    return str(header.get("name", source)), steps


def _json_lines(text: str, source: str) -> list[tuple[int, object]]:
    out: list[tuple[int, object]] = []
    for lineno, line in enumerate(text.splitlines(), start=1):
        if not line.strip():
            continue
        try:
            out.append((lineno, json.loads(line)))
        except (ValueError, RecursionError):  # JSONDecodeError, or nested too deep
            raise JoystickError(f"{source} line {lineno} is not JSON: replay a file written by --record.") from None
    return out


def _record_step(rec: object, where: str) -> Step | float:
    """One recorded line -> its Step, or the end's time (a float) for the `end` line."""
    bad = JoystickError(f"{where} is not a joystick record of t, axes and buttons: replay a file written by --record.")
    if not isinstance(rec, dict):
        raise bad
    try:
        t = float(rec["t"])
        if rec.get("end"):
            out: Step | float = t
        else:
            axes, buttons = tuple(int(v) for v in rec["axes"]), tuple(int(v) for v in rec["buttons"])
            out = Step(t, axes, buttons, bool(rec.get("connected", True)))
    except (KeyError, TypeError, ValueError, OverflowError):
        raise bad from None
    if not math.isfinite(t):
        raise bad
    return out


class ReplaySource(TimedSource):
    """`replay:FILE`: a recorded session played back with its timing."""

    @classmethod
    def from_file(cls, path: str, clock: Clock) -> ReplaySource:
        name, steps = parse_recording(_read_text(path, "replay"), path)
        return cls(name, path, steps, clock)
