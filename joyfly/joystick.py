"""The Linux joystick (js) API, read directly: no SDL, no evdev, no ROS.

A js device (`/dev/input/jsN`) delivers 8-byte `struct js_event {u32 time_ms; s16 value; u8 type; u8 number}`
records (include/uapi/linux/joystick.h). Axes run -32767..32767 (up on a stick is negative), buttons 1/0.
On open, and again after the kernel's 64-event queue overflows, the driver re-sends the whole state as events
flagged JS_EVENT_INIT (buttons first, then axes).

`open_joystick(spec, clock)` returns a `JoystickSource` for:
  - a js device: name and axis/button counts come from the JSIOCGNAME/JSIOCGAXES/JSIOCGBUTTONS ioctls; a read error
    (ENODEV: unplugged) gives `connected=False`, and the device is reopened automatically when it comes back;
  - a FIFO of js_event records (`mkfifo`): opened without blocking even when no writer exists yet; until the first
    writer connects and after it closes, `connected=False`; a new writer is picked up again;
  - a regular file of js_event records: read like `tail -f` (events appended later are picked up);
  - `script:FILE` and `replay:FILE`: virtual joysticks, see joyfly/virtual.py.
For a FIFO or a file the counts grow as events arrive and the name is the path.
"""

from __future__ import annotations

import errno
import fcntl
import glob
import logging
import os
import select
import stat
import struct
import time
from dataclasses import dataclass

from joyfly.types import Clock, JoyState, JoystickSource

log = logging.getLogger(__name__)

JS_EVENT_BUTTON = 0x01
JS_EVENT_AXIS = 0x02
JS_EVENT_INIT = 0x80
EVENT_FORMAT = "IhBB"
EVENT_SIZE = struct.calcsize(EVENT_FORMAT)  # 8
AXIS_MAX = 32767

# ioctl numbers (asm-generic/ioctl.h): _IOC(dir, type, nr, size) = dir << 30 | size << 16 | type << 8 | nr
_IOC_READ = 2
_JS_MAGIC = ord("j")
NAME_LEN = 128
REOPEN_INTERVAL_S = 0.5


def _ior(nr: int, size: int) -> int:
    return (_IOC_READ << 30) | (size << 16) | (_JS_MAGIC << 8) | nr


JSIOCGVERSION = _ior(0x01, 4)
JSIOCGAXES = _ior(0x11, 1)
JSIOCGBUTTONS = _ior(0x12, 1)
JSIOCGNAME = _ior(0x13, NAME_LEN)


class JoystickError(Exception):
    """A joystick problem a user can fix; str() is one sentence saying what happened and what to do."""


class NoDeviceError(JoystickError):
    """Nothing at the path (lists the js devices that do exist, or says there are none)."""


class PermissionDeniedError(JoystickError):
    """The device exists but we may not read it."""


class DeviceVanishedError(JoystickError):
    """The device went away while in use (unplugged, out of radio range)."""


def no_such_device_error(path: str, dev_dir: str = "/dev/input") -> JoystickError:
    others = [p for p in find_device_paths(dev_dir) if p != path]
    if others:
        return NoDeviceError(f"No joystick at {path}; joysticks present: {', '.join(others)} (pass one with --joy).")
    return NoDeviceError(
        f"No joystick at {path}, and none is connected (no {dev_dir}/js*): plug one in, or fly a virtual one with "
        "--joy script:examples/joystick_script.txt."
    )


def permission_error(path: str) -> JoystickError:
    return PermissionDeniedError(
        f"Permission denied opening {path}: run `sudo chmod a+rw {path}` for now, or add yourself to the input group "
        "(`sudo usermod -aG input $USER`, then log in again) or write a udev rule."
    )


def vanished_error(path: str) -> JoystickError:
    return DeviceVanishedError(f"The joystick {path} vanished (unplugged?): plug it back in and joyfly reopens it.")


# ---------------------------------------------------------------------------------------------------------- events


@dataclass(frozen=True, slots=True)
class JsEvent:
    time_ms: int
    value: int
    type: int
    number: int

    @property
    def is_init(self) -> bool:
        return bool(self.type & JS_EVENT_INIT)


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


# ---------------------------------------------------------------------------------------------------------- clocks


class MonotonicClock:
    """The wall clock (monotonic seconds): the default when no clock is injected (joyfly.clock has the others)."""

    def now(self) -> float:
        return time.monotonic()

    def sleep(self, seconds: float) -> None:
        if seconds > 0:
            time.sleep(seconds)


# ---------------------------------------------------------------------------------------------------------- device


@dataclass(frozen=True, slots=True)
class DeviceInfo:
    path: str
    name: str
    axes: int
    buttons: int
    kind: str  # "device", "fifo" or "file"


def _open_fd(path: str, dev_dir: str = "/dev/input") -> int:
    try:
        return os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    except FileNotFoundError:
        raise no_such_device_error(path, dev_dir) from None
    except PermissionError:
        raise permission_error(path) from None
    except OSError as exc:
        if exc.errno in (errno.ENODEV, errno.ENXIO):
            raise no_such_device_error(path, dev_dir) from None
        raise JoystickError(f"Cannot open {path} ({exc.strerror}): check the path given with --joy.") from None


def _kind_of(fd: int) -> str:
    mode = os.fstat(fd).st_mode
    if stat.S_ISCHR(mode):
        return "device"
    if stat.S_ISFIFO(mode):
        return "fifo"
    return "file"


def _ioctl_u8(fd: int, request: int) -> int | None:
    try:
        return fcntl.ioctl(fd, request, b"\0")[0]
    except OSError:
        return None


def _ioctl_name(fd: int) -> str | None:
    try:
        raw = fcntl.ioctl(fd, JSIOCGNAME, b"\0" * NAME_LEN)
    except OSError:
        return None
    return raw.split(b"\0", 1)[0].decode("utf-8", "replace").strip() or None


def probe_fd(fd: int, path: str) -> DeviceInfo:
    """Name and counts from the js ioctls; a FIFO or a file (no ioctls) gets name = path and counts 0."""
    kind = _kind_of(fd)
    if kind != "device":
        return DeviceInfo(path, path, 0, 0, kind)
    name = _ioctl_name(fd) or path
    return DeviceInfo(path, name, _ioctl_u8(fd, JSIOCGAXES) or 0, _ioctl_u8(fd, JSIOCGBUTTONS) or 0, kind)


def find_device_paths(dev_dir: str = "/dev/input") -> list[str]:
    """Every js* node in dev_dir, in numeric order (js2 before js10)."""
    paths = glob.glob(os.path.join(dev_dir, "js*"))
    return sorted(paths, key=lambda p: (len(p), p))


def list_devices(dev_dir: str = "/dev/input") -> list[DeviceInfo | JoystickError]:
    """Probe every js* node: a DeviceInfo each, or the JoystickError that stopped us (e.g. permission denied)."""
    found: list[DeviceInfo | JoystickError] = []
    for path in find_device_paths(dev_dir):
        try:
            fd = _open_fd(path, dev_dir)
        except JoystickError as exc:
            found.append(exc)
            continue
        try:
            found.append(probe_fd(fd, path))
        finally:
            os.close(fd)
    return found


class JsDevice:
    """A js device, a FIFO or a regular file of js_event records, read without ever blocking longer than asked."""

    def __init__(self, path: str, clock: Clock, dev_dir: str = "/dev/input") -> None:
        self.path = path
        self.clock = clock
        self.dev_dir = dev_dir
        self._fd: int | None = _open_fd(path, dev_dir)
        self.info = probe_fd(self._fd, path)
        self.name = self.info.name
        self.kind = self.info.kind
        self._tracker = JsStateTracker(self.info.axes, self.info.buttons)
        self._pending = b""
        # A FIFO is "connected" only while a writer is attached (we learn that from its first bytes).
        self.connected = self.kind != "fifo"
        self.last_error: JoystickError | None = None
        self._next_reopen_s = 0.0

    # -- public -----------------------------------------------------------------------------------------------------

    def poll(self, timeout_s: float) -> JoyState:
        """Read every event that has arrived, waiting at most timeout_s for the first one."""
        deadline = self.clock.now() + max(0.0, timeout_s)
        if self._fd is None and not self._try_reopen():
            self.clock.sleep(max(0.0, deadline - self.clock.now()))
            return self.state()
        if self.kind == "file":
            if not self._read_available():
                self.clock.sleep(max(0.0, timeout_s))
            return self.state()
        self._wait_readable(max(0.0, timeout_s))
        self._read_available()
        return self.state()

    def state(self) -> JoyState:
        return self._tracker.state(self.clock.now(), self.connected)

    def reopen(self) -> bool:
        """Try to open the path again (after the device vanished); True when it is back."""
        self._close_fd()
        try:
            self._fd = _open_fd(self.path, self.dev_dir)
        except JoystickError as exc:
            if not (isinstance(exc, NoDeviceError) and isinstance(self.last_error, DeviceVanishedError)):
                self.last_error = exc  # "vanished" stays the news until something else goes wrong
            return False
        info = probe_fd(self._fd, self.path)
        self.info, self.name = info, info.name
        self._tracker = JsStateTracker(info.axes, info.buttons)  # the kernel re-sends the state as INIT events
        self._pending = b""
        self.connected = self.kind != "fifo"
        if self.connected:
            self.last_error = None
            log.info("joystick %s is back", self.path)
        return True

    def close(self) -> None:
        self._close_fd()
        self.connected = False

    def fileno(self) -> int | None:
        return self._fd

    # -- internals --------------------------------------------------------------------------------------------------

    def _wait_readable(self, timeout_s: float) -> bool:
        if self._fd is None:
            return False
        try:
            ready, _, _ = select.select([self._fd], [], [], timeout_s)
        except InterruptedError:
            return False
        return bool(ready)

    def _read_available(self) -> bool:
        """Drain the fd; returns True when at least one whole event was applied."""
        got = False
        while self._fd is not None:
            try:
                data = os.read(self._fd, EVENT_SIZE * 64)
            except BlockingIOError:
                break
            except OSError as exc:
                self._lost(exc)
                break
            if not data:
                if not got:  # else report what arrived first: a FIFO's EOF is still there on the next poll
                    self._at_eof()
                break
            got = self._feed(data) or got
        return got

    def _feed(self, data: bytes) -> bool:
        events, self._pending = parse_events(self._pending + data)
        if self.kind == "fifo" and not self.connected:
            self.connected = True
            self.last_error = None
            log.info("writer attached to FIFO %s", self.path)
        for ev in events:
            self._tracker.apply(ev)
        return bool(events)

    def _at_eof(self) -> None:
        if self.kind == "file":
            return  # like tail -f: more records may be appended later
        if self.kind == "fifo":
            # The writer closed. Reopen at once so select() blocks again (a FIFO whose writer left stays readable at
            # EOF forever) and a new writer is picked up.
            was = self.connected
            self.reopen()
            if was:
                self.last_error = vanished_error(self.path)
                log.warning("%s", self.last_error)
            return
        self._lost(OSError(errno.ENODEV, "end of device"))

    def _lost(self, exc: OSError) -> None:
        log.warning("joystick %s read error: %s", self.path, exc)
        self._close_fd()
        self.connected = False
        self.last_error = vanished_error(self.path)
        self._next_reopen_s = self.clock.now() + REOPEN_INTERVAL_S

    def _try_reopen(self) -> bool:
        if self.clock.now() < self._next_reopen_s:
            return False
        self._next_reopen_s = self.clock.now() + REOPEN_INTERVAL_S
        return self.reopen()

    def _close_fd(self) -> None:
        if self._fd is not None:
            try:
                os.close(self._fd)
            finally:
                self._fd = None


def open_joystick(spec: str, clock: Clock | None = None, dev_dir: str = "/dev/input") -> JoystickSource:
    """A joystick source from `--joy`: a device/FIFO/file path, `script:FILE` or `replay:FILE`.

    Raises JoystickError (one sentence with the fix) when it cannot be opened.
    """
    clock = clock or MonotonicClock()
    if spec.startswith("script:"):
        from joyfly.virtual import ScriptSource

        return ScriptSource.from_file(spec[len("script:") :], clock)
    if spec.startswith("replay:"):
        from joyfly.virtual import ReplaySource

        return ReplaySource.from_file(spec[len("replay:") :], clock)
    return JsDevice(spec, clock, dev_dir)


def default_device(dev_dir: str = "/dev/input") -> str:
    """The first js device present, or a JoystickError saying none is connected."""
    paths = find_device_paths(dev_dir)
    if not paths:
        raise no_such_device_error(os.path.join(dev_dir, "js0"), dev_dir)
    return paths[0]
