"""Virtual joysticks: `script:FILE` (timed stick and button values) and `replay:FILE` (a recorded session).

Script format (one step a line; `#` starts a comment; blank lines are ignored)::

    <time> <name>=<value> [<name>=<value> ...] [end]

- `<time>`: seconds since the first poll() of the source (absolute, non-decreasing), or `+<seconds>` after the
  previous line's time.
- sticks, already in the flying convention (no profile signs, deadzone or expo apply): `forward` (+1 = fly north),
  `right` (+1 = fly east), `up` (+1 = climb, a centred throttle stick), `yaw` (+1 = turn clockwise), each -1..1.
- buttons, 1 (down) or 0 (up): `arm` (hold it 1 s to arm, or to disarm once landed), `takeoff`, `land`, `rtl`
  (alias `return`), `hold`, `offboard`, `deadman` (only acts when the profile configures a deadman button).
- `end`: the virtual joystick goes away (JoyState.connected False from then on, as if unplugged).
Values hold until changed. A button press must last longer than the caller's poll period to be seen (0.2 s is safe).

    # take off, fly 2 m/s forward for 3 s, land
    0     arm=1
    1.5   arm=0 takeoff=1
    +0.3  takeoff=0
    8     forward=1
    +3    forward=0
    +2    land=1
    +0.3  land=0
    +8    end

A script source reports the name "joyfly script", which selects the built-in `script` profile: axes 0..3 = forward,
right, up, yaw (scaled to +-32767 with the flying signs) and buttons 0..6 = arm, takeoff, land, rtl, hold, offboard,
deadman.

Recordings (`JoyRecorder`, `--record FILE`) are JSON lines: a header `{"joyfly_recording": 1, "name", "path"}`, then
one `{"t", "axes", "buttons", "connected"}` line per change of the raw JoyState (t in seconds since the first
record), and `{"t", "end": true}` on close. `replay:FILE` plays them back with their timing on the injected clock,
under the recorded device name (so the same profile matches), and reports connected False after the end.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import IO

from joyfly.joystick import AXIS_MAX, JoystickError
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
        raise JoystickError(f"No {what} file at {path}: check the path after '{what}:'.") from None
    except OSError as exc:
        raise JoystickError(f"Cannot read the {what} file {path} ({exc.strerror}): check the path.") from None


# ---------------------------------------------------------------------------------------------------------- record


class JoyRecorder:
    """Writes raw JoyStates as JSON lines, one line per change (see the module docstring)."""

    def __init__(self, out: str | IO[str], name: str, path: str) -> None:
        self._own = isinstance(out, str)
        self._out: IO[str] = open(out, "w", encoding="utf-8") if isinstance(out, str) else out  # noqa: SIM115
        self._t0: float | None = None
        self._last: tuple[tuple[int, ...], tuple[int, ...], bool] | None = None
        self._last_t = 0.0
        self._write({"joyfly_recording": 1, "name": name, "path": path})

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
    """`--record FILE`: the same source, also writing every change to out."""
    return RecordingSource(source, JoyRecorder(out, source.name, source.path))


# ---------------------------------------------------------------------------------------------------------- replay


def parse_recording(text: str, source: str = "recording") -> tuple[str, list[Step]]:
    """Recording text -> (recorded device name, Steps); the last step is connected False (the end)."""
    lines = [ln for ln in text.splitlines() if ln.strip()]
    try:
        header = json.loads(lines[0]) if lines else {}
        records = [json.loads(ln) for ln in lines[1:]]
    except json.JSONDecodeError as exc:
        raise JoystickError(f"{source} line {exc.lineno} is not JSON: replay a file written by --record.") from None
    if header.get("joyfly_recording") != 1:
        raise JoystickError(f"{source} is not a joyfly recording: replay a file written by --record.")
    steps, last = [], Step(0.0, (), ())
    for rec in records:
        if rec.get("end"):
            break
        last = Step(float(rec["t"]), tuple(rec["axes"]), tuple(rec["buttons"]), bool(rec.get("connected", True)))
        steps.append(last)
    end_t = max((float(r["t"]) for r in records if r.get("end")), default=last.t_s)
    steps.append(Step(end_t, last.axes, last.buttons, connected=False))
    return str(header.get("name", source)), steps


class ReplaySource(TimedSource):
    """`replay:FILE`: a recorded session played back with its timing."""

    @classmethod
    def from_file(cls, path: str, clock: Clock) -> ReplaySource:
        name, steps = parse_recording(_read_text(path, "replay"), path)
        return cls(name, path, steps, clock)
