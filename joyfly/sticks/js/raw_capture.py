"""`raw:FILE` for a regular file: a capture of a joystick's js_event records (`cat /dev/input/js0 > FILE`), checked
whole at open and played back with the records' own timing, as a `--record` recording is replayed.

A file is not a joystick: joyfly refuses at open, before any MAVLink is sent, a file whose records are not what the
kernel's joydev writes (`JsStreamCheck`: random bytes fail on their first record with 252 chances in 256), and a
file that holds no record or a piece of one. A capture ends at its last record: from then on the joystick is gone
(`JoyState.connected` False), which a flight takes for a lost joystick (hold, then land after --joy-timeout). A live
joystick is streamed through a FIFO or a pty instead (joyfly/sticks/js/reader.py), which waits for its writer.
"""

from __future__ import annotations

import os

from joyfly.sticks.js.events import (
    EVENT_SIZE,
    TIME_WRAP_MS,
    JoystickError,
    JsStateTracker,
    JsStreamCheck,
    parse_events,
    permission_error,
)
from joyfly.sticks.virtual import Step, TimedSource
from joyfly.types import Clock

CAPTURE_FIX = "capture a joystick with `cat /dev/input/js0 > FILE`, or fly a virtual one with --joy script:FILE"
MAX_CAPTURE_BYTES = 64 << 20  # 8 M records: hours of a joystick moving without pause


def capture_steps(data: bytes, where: str) -> list[Step]:
    """js_event records -> the joystick's full state at each record time (seconds after the first record), then a
    last Step that is the end (connected False). JoystickError (one sentence) at the first record joydev would never
    write, or when there is no whole record."""
    events, rest = parse_events(data)
    check, tracker = JsStreamCheck(), JsStateTracker()
    steps: list[Step] = []
    elapsed_ms, prev_ms = 0, None
    for index, ev in enumerate(events):
        why = check.check(ev)
        if why is not None:
            raise JoystickError(f"{where} is not a joystick capture: record {index + 1} (byte {index * EVENT_SIZE}) "
                                f"has {why}; {CAPTURE_FIX}.")
        elapsed_ms += 0 if prev_ms is None else (ev.time_ms - prev_ms) % TIME_WRAP_MS
        prev_ms = ev.time_ms
        tracker.apply(ev)
        step = Step(elapsed_ms / 1000.0, tuple(tracker.axes), tuple(tracker.buttons))
        if steps and steps[-1].t_s == step.t_s:
            steps[-1] = step
        else:
            steps.append(step)
    if not steps or rest:
        what = "holds no js_event record" if not steps else "ends in a piece of a record"
        raise JoystickError(f"{where} {what} ({len(data)} bytes; a js_event is {EVENT_SIZE}): {CAPTURE_FIX}.")
    last = steps[-1]
    return [*steps, Step(last.t_s, last.axes, last.buttons, connected=False)]


def read_capture(path: str) -> bytes:
    """The file's bytes, or JoystickError (one sentence)."""
    try:
        if os.path.getsize(path) > MAX_CAPTURE_BYTES:
            raise JoystickError(f"raw:{path} is larger than {MAX_CAPTURE_BYTES >> 20} MB, more than a joystick "
                                f"capture: {CAPTURE_FIX}.")
        with open(path, "rb") as fh:
            return fh.read()
    except PermissionError:
        raise permission_error(path) from None
    except OSError as exc:
        raise JoystickError(f"Cannot read raw:{path} ({exc.strerror}): check the path after 'raw:'.") from None


class RawCapture(TimedSource):
    """`raw:FILE` (a regular file): a joystick capture played with its own timing; `gone` once it has ended."""

    kind = "file"

    @classmethod
    def from_file(cls, path: str, clock: Clock) -> RawCapture:
        return cls(path, path, capture_steps(read_capture(path), f"raw:{path}"), clock)

    @property
    def span_s(self) -> float:
        return self._steps[-1].t_s

    @property
    def gone(self) -> str | None:
        """Why this joystick gives no sticks any more (its capture ended), or None while it plays."""
        if not self.ended:
            return None
        return (f"The joystick capture raw:{self.path} reached its end (its records span {self.span_s:.1f} s), so the "
                "joystick is gone: a capture plays with its own timing and ends at its last record; stream a live "
                "joystick through a FIFO instead (mkfifo, then `cat /dev/input/js0 > FIFO`).")
