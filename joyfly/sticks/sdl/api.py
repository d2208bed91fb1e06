"""The seam between joyfly and SDL2 (pysdl2 over the SDL 2.32 library from pysdl2-dll): every SDL call joyfly makes
goes through `SdlApi`, so the SDL source (joyfly/sticks/sdl/source.py) can be driven by SDL's own virtual joysticks
in tests, and a machine without a loadable SDL gets one sentence (`SdlUnavailable`) instead of a traceback.

SDL runs headless here: only the joystick and game-controller subsystems are started (no video, no window), with
background joystick events allowed (no window focus exists), SDL's own SIGINT/SIGTERM handlers off (joyfly's
Ctrl-C and SIGTERM handling must keep working) and, on Windows, SDL_HINT_JOYSTICK_THREAD (SDL reads raw input on a
thread of its own, as no window's message loop does it). SDL is not thread-safe for the event pump: the thread
that polls the source pumps SDL's events; SDL's virtual-joystick setters lock SDL's joystick mutex, so a test may
move a virtual stick from another thread.

What a device reads as (`read`), in the js API's units so profiles and mappings stay one code path:
  - a game controller (SDL's database, or a user mapping, knows it): SDL's standard layout, axes 0 left X, 1 left
    Y, 2 right X, 3 right Y (Y positive = pulled back, as on js), 4 left trigger, 5 right trigger (0 at rest);
    buttons 0 A, 1 B, 2 X, 3 Y, 4 Back, 5 Guide, 6 Start, 7 left stick, 8 right stick, 9 left shoulder, 10 right
    shoulder, 11-14 d-pad up/down/left/right, 15 misc, 16-19 paddles, 20 touchpad (SDL_GameControllerButton);
  - a plain joystick: its raw axes, then two axes per hat (x: left -32767 .. right 32767, y: up -32767 .. down
    32767, as joydev numbers hats after the other axes), then its buttons.
Axis values run -32767..32767 (SDL's -32768 is clamped, as joydev does).
"""

from __future__ import annotations

import ctypes
import os
import threading
import warnings
from dataclasses import dataclass
from enum import Enum
from typing import Any

from joyfly.sticks.js.events import AXIS_MAX, JoystickError

CONTROLLER_AXES = 6  # SDL_CONTROLLER_AXIS_MAX
CONTROLLER_BUTTONS = 21  # SDL_CONTROLLER_BUTTON_MAX
# SDL_HAT_UP 1, RIGHT 2, DOWN 4, LEFT 8
_HAT_UP, _HAT_RIGHT, _HAT_DOWN, _HAT_LEFT = 1, 2, 4, 8
RUMBLE_MAX = 0xFFFF


class SdlUnavailable(JoystickError):
    """SDL2 could not be loaded or started on this machine."""


class MappingError(JoystickError):
    """A game-controller mapping SDL refused (names the file or setting and the line)."""


@dataclass(frozen=True, slots=True)
class SdlDevice:
    """One device as SDL enumerates it now (index = SDL's device index, valid until the next hot-plug)."""

    index: int
    instance_id: int
    name: str
    guid: str
    is_controller: bool
    axes: int = -1  # the counts and rumble are known only once the device is opened (`describe`)
    buttons: int = -1
    hats: int = -1
    rumble: bool | None = None

    @property
    def kind(self) -> str:
        return "game controller" if self.is_controller else "joystick"


class Hotplug(Enum):
    ADDED = "added"
    REMOVED = "removed"


@dataclass(frozen=True, slots=True)
class Opened:
    """An open device: the SDL pointers behind it (controller is None for a plain joystick)."""

    joystick: Any
    controller: Any
    instance_id: int


def _clamp_axis(value: int) -> int:
    return max(-AXIS_MAX, min(AXIS_MAX, int(value)))


def hat_axes(hat: int) -> tuple[int, int]:
    """An SDL hat bitmask as two js-style axes (x left -, right +; y up -, down +)."""
    x = (AXIS_MAX if hat & _HAT_RIGHT else 0) - (AXIS_MAX if hat & _HAT_LEFT else 0)
    y = (AXIS_MAX if hat & _HAT_DOWN else 0) - (AXIS_MAX if hat & _HAT_UP else 0)
    return x, y


def _load_sdl2() -> Any:
    """Import pysdl2 (which loads the SDL library); its 'using the binaries from pysdl2-dll' notice is not news."""
    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            import sdl2
    except Exception as exc:  # ImportError, or RuntimeError from pysdl2 when no SDL library loads
        raise SdlUnavailable(f"SDL2 could not be loaded ({str(exc).strip().rstrip('.')}); install pysdl2 and "
                             "pysdl2-dll, or use a /dev/input/js* device.") from None
    return sdl2


class SdlApi:
    """SDL's joystick and game-controller subsystems, started once per process (`sdl_api()`)."""

    def __init__(self) -> None:
        sdl = _load_sdl2()
        self.sdl = sdl
        for hint, value in ((sdl.SDL_HINT_NO_SIGNAL_HANDLERS, b"1"),  # joyfly's Ctrl-C/SIGTERM stay joyfly's
                            (sdl.SDL_HINT_JOYSTICK_ALLOW_BACKGROUND_EVENTS, b"1"),  # no window has the focus
                            (sdl.SDL_HINT_JOYSTICK_THREAD, b"1")):  # Windows: raw input without a window's loop
            sdl.SDL_SetHint(hint, value)
        if sdl.SDL_InitSubSystem(sdl.SDL_INIT_JOYSTICK | sdl.SDL_INIT_GAMECONTROLLER) != 0:
            raise SdlUnavailable(f"SDL2 could not start its joystick subsystem ({self.error()}): use a "
                                 "/dev/input/js* device.")
        self._event = sdl.SDL_Event()

    def error(self) -> str:
        return (self.sdl.SDL_GetError() or b"no reason given").decode("utf-8", "replace").strip().rstrip(".")

    # -- enumeration ------------------------------------------------------------------------------------------------

    def devices(self) -> list[SdlDevice]:
        """Every device now (pumps SDL's events first, so that devices plugged in since show up)."""
        self.pump()
        return self.devices_now()

    def devices_now(self) -> list[SdlDevice]:
        """Every device SDL knows now, without pumping (the events stay for the source that pumps)."""
        return [self.device(i) for i in range(self.sdl.SDL_NumJoysticks())]

    def device(self, index: int) -> SdlDevice:
        sdl = self.sdl
        name = sdl.SDL_JoystickNameForIndex(index) or b""
        return SdlDevice(index, int(sdl.SDL_JoystickGetDeviceInstanceID(index)), name.decode("utf-8", "replace"),
                         self.guid_string(sdl.SDL_JoystickGetDeviceGUID(index)), bool(sdl.SDL_IsGameController(index)))

    def guid_string(self, guid: Any) -> str:
        buf = ctypes.create_string_buffer(33)
        self.sdl.SDL_JoystickGetGUIDString(guid, buf, 33)
        return buf.value.decode("ascii")

    def describe(self, device: SdlDevice) -> SdlDevice:
        """The device with its counts and rumble filled in (opens it briefly)."""
        opened = self.open(device.index, device.is_controller)
        if opened is None:
            return device
        try:
            js = opened.joystick
            sdl = self.sdl
            return SdlDevice(device.index, device.instance_id, device.name, device.guid, device.is_controller,
                             sdl.SDL_JoystickNumAxes(js), sdl.SDL_JoystickNumButtons(js), sdl.SDL_JoystickNumHats(js),
                             self.has_rumble(opened))
        finally:
            self.close(opened)

    # -- one device -------------------------------------------------------------------------------------------------

    def open(self, index: int, as_controller: bool) -> Opened | None:
        sdl = self.sdl
        if as_controller:
            gc = sdl.SDL_GameControllerOpen(index)
            if not gc:
                return None
            js = sdl.SDL_GameControllerGetJoystick(gc)
            return Opened(js, gc, int(sdl.SDL_JoystickInstanceID(js)))
        js = sdl.SDL_JoystickOpen(index)
        return Opened(js, None, int(sdl.SDL_JoystickInstanceID(js))) if js else None

    def close(self, opened: Opened) -> None:
        if opened.controller is not None:
            self.sdl.SDL_GameControllerClose(opened.controller)
        else:
            self.sdl.SDL_JoystickClose(opened.joystick)

    def attached(self, opened: Opened) -> bool:
        return bool(self.sdl.SDL_JoystickGetAttached(opened.joystick))

    def read(self, opened: Opened) -> tuple[tuple[int, ...], tuple[int, ...]]:
        """(axes, buttons) in js units (see the module docstring for the layout)."""
        sdl = self.sdl
        if opened.controller is not None:
            gc = opened.controller
            axes = tuple(_clamp_axis(sdl.SDL_GameControllerGetAxis(gc, a)) for a in range(CONTROLLER_AXES))
            return axes, tuple(int(sdl.SDL_GameControllerGetButton(gc, b)) for b in range(CONTROLLER_BUTTONS))
        js = opened.joystick
        raw = [_clamp_axis(sdl.SDL_JoystickGetAxis(js, a)) for a in range(sdl.SDL_JoystickNumAxes(js))]
        for h in range(sdl.SDL_JoystickNumHats(js)):
            raw.extend(hat_axes(sdl.SDL_JoystickGetHat(js, h)))
        buttons = tuple(int(sdl.SDL_JoystickGetButton(js, b)) for b in range(sdl.SDL_JoystickNumButtons(js)))
        return tuple(raw), buttons

    def has_rumble(self, opened: Opened) -> bool:
        if opened.controller is not None:
            return bool(self.sdl.SDL_GameControllerHasRumble(opened.controller))
        return bool(self.sdl.SDL_JoystickHasRumble(opened.joystick))

    def rumble(self, opened: Opened, low: float, high: float, duration_ms: int) -> bool:
        """Start a rumble (motor strengths 0..1); False when the device has none (nothing else happens)."""
        lo, hi = (round(RUMBLE_MAX * max(0.0, min(1.0, v))) for v in (low, high))
        if opened.controller is not None:
            return self.sdl.SDL_GameControllerRumble(opened.controller, lo, hi, duration_ms) == 0
        return self.sdl.SDL_JoystickRumble(opened.joystick, lo, hi, duration_ms) == 0

    # -- events and mappings ----------------------------------------------------------------------------------------

    def pump(self) -> tuple[list[tuple[Hotplug, int]], bool]:
        """Pump SDL's events: (hot-plug events as (ADDED, device index) / (REMOVED, instance id), whether any input
        event arrived). Call it from the thread that polls the source."""
        sdl, event = self.sdl, self._event
        sdl.SDL_PumpEvents()
        plugs: list[tuple[Hotplug, int]] = []
        moved = False
        while sdl.SDL_PollEvent(ctypes.byref(event)):
            kind = event.type
            if kind == sdl.SDL_JOYDEVICEADDED:
                plugs.append((Hotplug.ADDED, int(event.jdevice.which)))
            elif kind == sdl.SDL_JOYDEVICEREMOVED:
                plugs.append((Hotplug.REMOVED, int(event.jdevice.which)))
            elif sdl.SDL_JOYAXISMOTION <= kind <= sdl.SDL_CONTROLLERTOUCHPADUP:
                moved = True
        return plugs, moved

    def add_mapping(self, line: str) -> str | None:
        """Give SDL one game-controller mapping line; None when taken, else SDL's reason."""
        if self.sdl.SDL_GameControllerAddMapping(line.encode("utf-8")) < 0:
            return self.error()
        return None

    def platform(self) -> str:
        return str(self.sdl.SDL_GetPlatform().decode("utf-8"))


_API: SdlApi | None = None
_API_LOCK = threading.Lock()


def sdl_api() -> SdlApi:
    """The process's SdlApi, started on first use; SdlUnavailable (one sentence) when SDL cannot be loaded."""
    global _API
    with _API_LOCK:
        if _API is None:
            _API = SdlApi()
        return _API
