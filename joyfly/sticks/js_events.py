"""The Linux joystick (js) API's wire format: 8-byte `struct js_event {u32 time_ms; s16 value; u8 type; u8 number}`
records (include/uapi/linux/joystick.h), the state they build, and the joystick errors a user can fix.

Axes run -32767..32767 (up on a stick is negative), buttons 1/0. On open, and again after the kernel's 64-event queue
overflows, the driver re-sends the whole state as events flagged JS_EVENT_INIT (buttons first, then axes).
No I/O here: joyfly/sticks/joystick.py reads devices, joyfly/sticks/virtual.py plays scripts and recordings.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

from joyfly.types import JoyState

JS_EVENT_BUTTON = 0x01
JS_EVENT_AXIS = 0x02
JS_EVENT_INIT = 0x80
EVENT_FORMAT = "IhBB"
EVENT_SIZE = struct.calcsize(EVENT_FORMAT)  # 8
AXIS_MAX = 32767


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
