"""The Linux joystick (js) API's wire format: 8-byte `struct js_event {u32 time_ms; s16 value; u8 type; u8 number}`
records (include/uapi/linux/joystick.h), the state they build, and the joystick errors a user can fix.

Axes run -32767..32767 (up on a stick is negative), buttons 1/0. On open, and again after the kernel's 64-event queue
overflows, the driver re-sends the whole state as events flagged JS_EVENT_INIT (buttons first, then axes).
`JsStreamCheck` tells js_event records from bytes that merely come in 8-byte pieces (drivers/input/joydev.c is what
writes real ones). No I/O here: joyfly/sticks/js/reader.py reads devices, joyfly/sticks/js/raw_capture.py captures.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

from joyfly.sticks.examples import virtual_joystick_hint
from joyfly.types import JoyState

JS_EVENT_BUTTON = 0x01
JS_EVENT_AXIS = 0x02
JS_EVENT_INIT = 0x80
EVENT_FORMAT = "IhBB"
EVENT_SIZE = struct.calcsize(EVENT_FORMAT)  # 8
AXIS_MAX = 32767
ABS_CNT = 64  # the input layer's absolute axes (include/uapi/linux/input-event-codes.h): joydev numbers fewer
TIME_WRAP_MS = 1 << 32  # time_ms is the kernel's jiffies in ms, a u32 that wraps (5 minutes after boot, first)


class JoystickError(Exception):
    """A joystick problem a user can fix; str() is one sentence saying what happened and what to do."""


class NoDeviceError(JoystickError):
    """Nothing at the path (lists the js devices that do exist, or says there are none)."""


class PermissionDeniedError(JoystickError):
    """The device exists but we may not read it."""


class DeviceVanishedError(JoystickError):
    """The device went away while in use (unplugged, out of radio range)."""


def permission_error(path: str) -> JoystickError:
    return PermissionDeniedError(
        f"Permission denied opening {path}: run `sudo chmod a+rw {path}` for now, or add yourself to the input group "
        "(`sudo usermod -aG input $USER`, then log in again) or write a udev rule."
    )


def vanished_error(path: str) -> JoystickError:
    return DeviceVanishedError(f"The joystick {path} vanished (unplugged?): plug it back in and joyfly reopens it.")


def not_js_events_error(path: str, record: int, why: str) -> JoystickError:
    """A FIFO, a pty or a device that sent a record joydev never writes (`why`: JsStreamCheck's words)."""
    return JoystickError(f"{path} sends something other than js_event records (record {record} has {why}): joyfly "
                         "stopped reading it; give --joy a joystick device, or a FIFO fed a joystick's records "
                         "(`cat /dev/input/js0 > FIFO`).")


@dataclass(frozen=True, slots=True)
class JsEvent:
    time_ms: int
    value: int
    type: int
    number: int


def pack_event(kind: int, number: int, value: int, time_ms: int = 0) -> bytes:
    """One js_event record; kind is JS_EVENT_AXIS or JS_EVENT_BUTTON (or'ed with JS_EVENT_INIT if wanted)."""
    return struct.pack(EVENT_FORMAT, time_ms & 0xFFFFFFFF, value, kind, number)


def parse_events(data: bytes) -> tuple[list[JsEvent], bytes]:
    """Split bytes into whole js_event records; returns (events, leftover bytes of a partial record)."""
    whole = len(data) - len(data) % EVENT_SIZE
    events = [JsEvent(*rec) for rec in struct.iter_unpack(EVENT_FORMAT, data[:whole])]
    return events, data[whole:]


class JsStateTracker:
    """Axes and buttons state built from js_events; lists grow when an index beyond the known count arrives."""

    def __init__(self, n_axes: int = 0, n_buttons: int = 0) -> None:
        self.axes = [0] * n_axes
        self.buttons = [0] * n_buttons
        self.events_seen = 0

    def apply(self, ev: JsEvent) -> None:
        kind = ev.type & ~JS_EVENT_INIT
        if kind == JS_EVENT_AXIS:
            _set_grow(self.axes, ev.number, max(-AXIS_MAX, min(AXIS_MAX, ev.value)))
        elif kind == JS_EVENT_BUTTON:
            _set_grow(self.buttons, ev.number, 1 if ev.value else 0)
        else:
            return
        self.events_seen += 1

    def state(self, time_s: float, connected: bool) -> JoyState:
        return JoyState(time_s=time_s, axes=tuple(self.axes), buttons=tuple(self.buttons), connected=connected)


def _set_grow(values: list[int], index: int, value: int) -> None:
    if index >= len(values):
        values.extend([0] * (index + 1 - len(values)))
    values[index] = value


class JsStreamCheck:
    """Whether records are what joydev writes, one record at a time: `check(ev)` returns None, or why not (words to
    follow "record N has ..."). What joydev never writes:
    - a type other than JS_EVENT_BUTTON or JS_EVENT_AXIS, each optionally with JS_EVENT_INIT;
    - a button value other than 0 or 1 (joydev_event passes EV_KEY 0/1 and drops autorepeat's 2);
    - a number at or beyond the count of its kind: the count the device declares (JSIOCGAXES/JSIOCGBUTTONS, given
      here), else the count the leading INIT events declare (joydev sends one per axis and per button on open), else
      ABS_CNT for an axis;
    - a time before the previous record's (modulo the u32 wrap).
    """

    def __init__(self, axes: int = 0, buttons: int = 0) -> None:
        self.declared = {JS_EVENT_AXIS: axes, JS_EVENT_BUTTON: buttons}  # 0: not declared (yet)
        self._leading = not (axes or buttons)  # the INIT events at the start declare the counts
        self._prev_ms: int | None = None
        self.records = 0  # checked so far, the last one included

    def check(self, ev: JsEvent) -> str | None:
        self.records += 1
        kind = ev.type & ~JS_EVENT_INIT
        if kind not in (JS_EVENT_AXIS, JS_EVENT_BUTTON):
            return (f"type 0x{ev.type:02x}, where a js_event has 0x01 (button) or 0x02 (axis), plus 0x80 for the "
                    "initial state")
        if kind == JS_EVENT_BUTTON and ev.value not in (0, 1):
            return f"button {ev.number} at {ev.value}, where a button is 0 or 1"
        if self._prev_ms is not None and (ev.time_ms - self._prev_ms) % TIME_WRAP_MS >= TIME_WRAP_MS // 2:
            return f"time {ev.time_ms} ms, before the {self._prev_ms} ms of the record before it"
        self._prev_ms = ev.time_ms
        return self._check_number(kind, ev)

    def _check_number(self, kind: int, ev: JsEvent) -> str | None:
        word, words = ("axis", "axes") if kind == JS_EVENT_AXIS else ("button", "buttons")
        if self._leading and ev.type & JS_EVENT_INIT:
            self.declared[kind] = max(self.declared[kind], ev.number + 1)
            return None if kind == JS_EVENT_BUTTON or ev.number < ABS_CNT else f"axis {ev.number}, beyond {ABS_CNT}"
        self._leading = False
        count = self.declared[kind] or (ABS_CNT if kind == JS_EVENT_AXIS else 0)
        if count and ev.number >= count:
            return f"{word} {ev.number}, where the joystick has {count} {word if count == 1 else words}"
        return None


def names_no_file_error(spec: str) -> JoystickError:
    """`--joy script:` (or replay:, raw:, or nothing) names no file: say what --joy takes."""
    return JoystickError(f"--joy {spec!r} names no file: give a device (/dev/input/js0), a FIFO, raw:FILE, "
                         f"script:FILE or replay:FILE, for example {virtual_joystick_hint()}.")


def no_such_device_error(path: str, dev_dir: str, present: list[str]) -> JoystickError:
    """No joystick at `path`: name the ones `present` in `dev_dir`, or say how to fly without one."""
    others = [p for p in present if p != path]
    if others:
        return NoDeviceError(f"No joystick at {path}; joysticks present: {', '.join(others)} (pass one with --joy).")
    return NoDeviceError(f"No joystick at {path}, and none is connected (no {dev_dir}/js*): plug one in, or fly a "
                         f"virtual one with {virtual_joystick_hint()}.")
