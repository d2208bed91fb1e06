"""The Linux joystick (js) API, read directly: no SDL, no evdev, no ROS (the record format: joyfly/sticks/js/events.py).

`open_joystick(spec, clock)` returns a `JoystickSource` for what `--joy` names:
  - a js device: name and axis/button counts come from the JSIOCGNAME/JSIOCGAXES/JSIOCGBUTTONS ioctls; a read error
    (ENODEV: unplugged) gives `connected=False`, and the device is reopened automatically when it comes back;
  - a FIFO of js_event records (`mkfifo`): opened without blocking even when no writer exists yet; until the first
    writer connects and after it closes, `connected=False`; a new writer is picked up again;
  - a pseudo-terminal carrying js_event records (e.g. `socat` forwarding a remote joystick), read like a device;
  - a recording written by `--record` (its first line says so): replayed, as `replay:FILE` does;
  - `raw:FILE`: a capture (`cat /dev/input/js0 > FILE`), checked and played by joyfly/sticks/js/raw_capture.py; or a
    character device that is no joystick, read as one; `script:FILE`, `replay:FILE`: joyfly/sticks/virtual.py.
Anything else is refused at open, before a vehicle is touched: a regular file that is no recording (without raw:
joyfly takes no file for a joystick), a directory, a character device that answers neither the js ioctls nor is a
pty (/dev/null, /dev/urandom, an evdev node). Only a FIFO waits for its writer. What a FIFO, a pty or a device sends
is checked record by record (events.JsStreamCheck): the first one joydev never writes stops the reading for good
(`gone`: before take-off the session ends with that sentence; in flight it is a lost joystick). For a FIFO the counts
grow as events arrive and the name is the path.
"""

from __future__ import annotations

import errno
import fcntl
import glob
import logging
import os
import select
import stat
from dataclasses import dataclass

from joyfly.sticks.js.events import (
    AXIS_MAX,
    EVENT_FORMAT,
    EVENT_SIZE,
    JS_EVENT_AXIS,
    JS_EVENT_BUTTON,
    JS_EVENT_INIT,
    DeviceVanishedError,
    JoystickError,
    JsEvent,
    JsStateTracker,
    JsStreamCheck,
    NoDeviceError,
    PermissionDeniedError,
    names_no_file_error,
    no_such_device_error,
    not_js_events_error,
    pack_event,
    parse_events,
    permission_error,
    vanished_error,
)
from joyfly.sticks.js.raw_capture import RawCapture
from joyfly.sticks.virtual import ReplaySource, ScriptSource, is_recording
from joyfly.types import Clock, JoyState, JoystickSource
from px4common.clock import WallClock

__all__ = [  # the record format is re-exported: callers import the joystick side from here
    "AXIS_MAX", "EVENT_FORMAT", "EVENT_SIZE", "JS_EVENT_AXIS", "JS_EVENT_BUTTON", "JS_EVENT_INIT", "DeviceInfo",
    "DeviceVanishedError", "JoystickError", "JsDevice", "JsEvent", "JsStateTracker",
    "NoDeviceError", "PermissionDeniedError", "default_device", "find_device_paths", "list_devices", "open_joystick",
    "pack_event", "parse_events", "probe_fd",
]

log = logging.getLogger(__name__)

# ioctl numbers (asm-generic/ioctl.h): _IOC(dir, type, nr, size) = dir << 30 | size << 16 | type << 8 | nr
_IOC_READ = 2
_JS_MAGIC = ord("j")
NAME_LEN = 128
REOPEN_INTERVAL_S = 0.5
# A joystick's kernel queue holds 64 events, one read; a source that never runs dry (a pty flooded with records) is
# read at most this many times per poll, so the session loop, its timeouts and Ctrl-C keep running.
MAX_READS_PER_POLL = 16


def _ior(nr: int, size: int) -> int:
    return (_IOC_READ << 30) | (size << 16) | (_JS_MAGIC << 8) | nr


JSIOCGVERSION = _ior(0x01, 4)
JSIOCGAXES = _ior(0x11, 1)
JSIOCGBUTTONS = _ior(0x12, 1)
JSIOCGNAME = _ior(0x13, NAME_LEN)


# ---------------------------------------------------------------------------------------------------------- device


@dataclass(frozen=True, slots=True)
class DeviceInfo:
    path: str
    name: str
    axes: int
    buttons: int
    kind: str  # "device", "fifo" or "file" (what open_source_fd accepts)


def _open_fd(path: str, dev_dir: str = "/dev/input") -> int:
    try:
        return os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    except FileNotFoundError:
        raise no_such_device_error(path, dev_dir, find_device_paths(dev_dir)) from None
    except PermissionError:
        raise permission_error(path) from None
    except OSError as exc:
        if exc.errno in (errno.ENODEV, errno.ENXIO):
            raise no_such_device_error(path, dev_dir, find_device_paths(dev_dir)) from None
        raise JoystickError(f"Cannot open {path} ({exc.strerror}): check the path given with --joy.") from None


def _kind_of(fd: int) -> str:
    mode = os.fstat(fd).st_mode
    if stat.S_ISCHR(mode):
        return "device"
    if stat.S_ISFIFO(mode):
        return "fifo"
    if stat.S_ISREG(mode):
        return "file"
    return "directory" if stat.S_ISDIR(mode) else "other"


# Linux's Unix98 pty slaves (/dev/pts/N): UNIX98_PTY_SLAVE_MAJOR 136 and the 7 majors after it
# (include/uapi/linux/major.h, UNIX98_PTY_MAJOR_COUNT 8).
PTY_SLAVE_MAJORS = range(136, 144)
JOYSTICKS = "a /dev/input/js* device, a FIFO of js_event records, or script:FILE"


def _is_joystick_or_pty(fd: int) -> bool:
    """A joystick driver answers JSIOCGVERSION (drivers/input/joydev.c); a pty is a stream someone set up."""
    try:
        fcntl.ioctl(fd, JSIOCGVERSION, b"\0" * 4)
        return True
    except OSError:
        return os.major(os.fstat(fd).st_rdev) in PTY_SLAVE_MAJORS


def refusal(fd: int, path: str, raw: bool = False) -> str | None:
    """Why the open file `fd` cannot be a joystick (one sentence), or None when it can; `raw` (the `raw:` spec) takes
    the user's word for a character device (a regular file under raw: is a capture: joyfly/sticks/js/raw_capture.py)."""
    kind = _kind_of(fd)
    if kind == "directory":
        return f"{path} is a directory, not a joystick: pass {JOYSTICKS}."
    if kind == "other":
        return f"{path} is neither a joystick device nor a FIFO: pass {JOYSTICKS}."
    if kind == "fifo" or (kind == "device" and (raw or _is_joystick_or_pty(fd))):
        return None
    if kind == "file":
        return (f"{path} is a regular file but not a joyfly recording (--record), so it is not read as a joystick: "
                f"pass raw:{path} if it holds js_event records, else {JOYSTICKS}.")
    return (f"{path} is a character device but not a joystick (it does not answer the joystick ioctls): pass a "
            f"/dev/input/js* device, or raw:{path} if it really carries js_event records.")


def open_source_fd(path: str, dev_dir: str = "/dev/input", raw: bool = False) -> int:
    """Open path without blocking and check it can be a joystick; JoystickError (one sentence) when not."""
    fd = _open_fd(path, dev_dir)
    why = refusal(fd, path, raw)
    if why is not None:
        os.close(fd)
        raise JoystickError(why)
    return fd


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
    """A js device, a FIFO or a pty (or, with raw:, another character device) of js_event records, read without ever
    blocking longer than asked. Refuses at open what cannot be a joystick (see `refusal`), and again on every reopen;
    stops for good at the first record that is not a js_event (`gone`)."""

    def __init__(self, path: str, clock: Clock, dev_dir: str = "/dev/input", raw: bool = False) -> None:
        self.path, self.clock, self.dev_dir, self.raw = path, clock, dev_dir, raw
        self.refused: JoystickError | None = None  # what it sent is not js_event records: not read again
        self._fd: int | None = open_source_fd(path, dev_dir, raw)
        self.info = probe_fd(self._fd, path)
        self.name = self.info.name
        self.kind = self.info.kind
        self._tracker = JsStateTracker(self.info.axes, self.info.buttons)
        self._check = JsStreamCheck(self.info.axes, self.info.buttons)
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
        self._wait_readable(max(0.0, timeout_s))
        self._read_available()
        return self.state()

    def state(self) -> JoyState:
        return self._tracker.state(self.clock.now(), self.connected)

    def reopen(self) -> bool:
        """Try to open the path again (after the device vanished); True when it is back."""
        self._close_fd()
        try:
            self._fd = open_source_fd(self.path, self.dev_dir, self.raw)
        except JoystickError as exc:
            if not (isinstance(exc, NoDeviceError) and isinstance(self.last_error, DeviceVanishedError)):
                self.last_error = exc  # "vanished" stays the news until something else goes wrong
            return False
        info = probe_fd(self._fd, self.path)
        self.info, self.name = info, info.name
        self._tracker = JsStateTracker(info.axes, info.buttons)  # the kernel re-sends the state as INIT events
        self._check = JsStreamCheck(info.axes, info.buttons)  # a new stream (a FIFO's new writer)
        self._pending = b""
        self.connected = self.kind != "fifo"
        if self.connected:
            self.last_error = None
            log.info("joystick %s is back", self.path)
        return True

    @property
    def gone(self) -> str | None:
        """Why this source gives no sticks any more (it sent something other than js_event records), or None."""
        return None if self.refused is None else str(self.refused)

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
        """Drain the fd, MAX_READS_PER_POLL reads at most; returns True when at least one whole event was applied."""
        got = False
        for _ in range(MAX_READS_PER_POLL):
            if self._fd is None:
                break
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
            why = self._check.check(ev)
            if why is not None:
                self._refuse(why)
                return False
            self._tracker.apply(ev)
        return bool(events)

    def _refuse(self, why: str) -> None:
        self._give_up(not_js_events_error(self.path, self._check.records, why))

    def _give_up(self, error: JoystickError) -> None:
        """Stop reading for good: what this source sends is no joystick's (`gone` says why)."""
        self.refused = self.last_error = error
        log.warning("%s", error)
        self._close_fd()
        self.connected = False

    def _at_eof(self) -> None:
        if self.kind == "fifo":
            # The writer closed. Reopen at once so select() blocks again (a FIFO whose writer left stays readable at
            # EOF forever) and a new writer is picked up.
            was = self.connected
            self.reopen()
            if was:
                self.last_error = vanished_error(self.path)
                log.warning("%s", self.last_error)
            return
        if self.raw and self._check.records == 0:  # a joystick never reads empty (it blocks, or fails unplugged)
            self._give_up(JoystickError(f"raw:{self.path} ended before its first js_event record (it reads empty), so "
                                        f"it is not a joystick: pass {JOYSTICKS}."))
            return
        self._lost(OSError(errno.ENODEV, "end of device"))

    def _lost(self, exc: OSError) -> None:
        log.warning("joystick %s read error: %s", self.path, exc)
        self._close_fd()
        self.connected = False
        self.last_error = vanished_error(self.path)
        self._next_reopen_s = self.clock.now() + REOPEN_INTERVAL_S

    def _try_reopen(self) -> bool:
        if self.refused is not None or self.clock.now() < self._next_reopen_s:
            return False
        self._next_reopen_s = self.clock.now() + REOPEN_INTERVAL_S
        return self.reopen()

    def _close_fd(self) -> None:
        if self._fd is not None:
            try:
                os.close(self._fd)
            finally:
                self._fd = None


RAW_PREFIX = "raw:"


def open_joystick(spec: str, clock: Clock | None = None, dev_dir: str = "/dev/input") -> JoystickSource:
    """A joystick source from `--joy`: a device/FIFO/pty path, a --record recording, `raw:FILE`, `script:FILE` or
    `replay:FILE` (see the module docstring).

    Raises JoystickError (one sentence with the fix) when it cannot be opened or cannot be a joystick.
    """
    clock = clock or WallClock()
    prefix, _, rest = spec.partition(":")
    if not spec or (f"{prefix}:" in ("script:", "replay:", RAW_PREFIX) and not rest):
        raise names_no_file_error(spec)
    if spec.startswith("script:"):
        return ScriptSource.from_file(spec[len("script:") :], clock)
    if spec.startswith("replay:"):
        return ReplaySource.from_file(spec[len("replay:") :], clock)
    if spec.startswith(RAW_PREFIX):
        path = spec[len(RAW_PREFIX) :]
        return RawCapture.from_file(path, clock) if os.path.isfile(path) else JsDevice(path, clock, dev_dir, raw=True)
    if is_recording(spec):
        return ReplaySource.from_file(spec, clock)
    return JsDevice(spec, clock, dev_dir)


def default_device(dev_dir: str = "/dev/input") -> str:
    """The first js device present, or a JoystickError saying none is connected."""
    paths = find_device_paths(dev_dir)
    if not paths:
        raise no_such_device_error(os.path.join(dev_dir, "js0"), dev_dir, [])
    return paths[0]
