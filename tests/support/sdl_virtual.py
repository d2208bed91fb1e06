"""SDL virtual joysticks for tests (SDL_JoystickAttachVirtualEx, SDL >= 2.24): SDL's joystick and game-controller
APIs read them exactly like hardware, in this process only. `VirtualPad.controller()` is a game controller in SDL's
standard layout (6 axes, 15 buttons: A B X Y Back Guide Start LS RS LB RB and the d-pad), with rumble that records
its calls; `VirtualPad.joystick()` a plain joystick SDL does not know as a game controller.

Stick values are given in the flying sense -1..1 of SDL's raw axis (Y axes positive = pulled back). The setters lock
SDL's joystick mutex, so a test may call them from any thread while joyfly's thread pumps SDL's events.
"""

from __future__ import annotations

import ctypes
from typing import Any

from joyfly.sticks.sdl.api import sdl_api

# SDL_GameControllerButton numbers of the standard layout
A, B, X, Y, BACK, GUIDE, START = range(7)
# SDL_GameControllerAxis numbers
LEFT_X, LEFT_Y, RIGHT_X, RIGHT_Y, TRIGGER_LEFT, TRIGGER_RIGHT = range(6)


class VirtualPad:
    def __init__(self, name: str, kind: int, naxes: int, nbuttons: int, nhats: int = 0, vendor: int = 0x1209,
                 product: int = 0x0001, rumble: bool = True) -> None:
        api = sdl_api()
        self.sdl = sdl = api.sdl
        self.rumbles: list[tuple[int, int, int]] = []  # (low, high, SDL ticks ms) per call
        desc = sdl.SDL_VirtualJoystickDesc()
        desc.version = sdl.SDL_VIRTUAL_JOYSTICK_DESC_VERSION
        desc.type, desc.naxes, desc.nbuttons, desc.nhats = kind, naxes, nbuttons, nhats
        desc.vendor_id, desc.product_id = vendor, product
        self._name = name.encode()
        desc.name = self._name
        rumble_type = dict(sdl.SDL_VirtualJoystickDesc._fields_)["Rumble"]
        self._on_rumble = rumble_type(self._rumble) if rumble else rumble_type()
        desc.Rumble = self._on_rumble
        self._desc = desc  # SDL keeps pointers into it
        index = sdl.SDL_JoystickAttachVirtualEx(ctypes.byref(desc))
        assert index >= 0, sdl.SDL_GetError()
        self.instance_id = int(sdl.SDL_JoystickGetDeviceInstanceID(index))
        self._js: Any = sdl.SDL_JoystickOpen(index)  # the setters need it open; joyfly opens its own handle
        self.attached = True

    @classmethod
    def controller(cls, name: str = "Virtual Pad", product: int = 0x0001, rumble: bool = True) -> VirtualPad:
        sdl = sdl_api().sdl
        return cls(name, sdl.SDL_JOYSTICK_TYPE_GAMECONTROLLER, 6, 15, product=product, rumble=rumble)

    @classmethod
    def joystick(cls, name: str = "Virtual Stick", naxes: int = 4, nbuttons: int = 8, nhats: int = 1,
                 product: int = 0x0002) -> VirtualPad:
        sdl = sdl_api().sdl
        return cls(name, sdl.SDL_JOYSTICK_TYPE_UNKNOWN, naxes, nbuttons, nhats, product=product, rumble=False)

    def _rumble(self, userdata: Any, low: int, high: int) -> int:
        self.rumbles.append((low, high, int(self.sdl.SDL_GetTicks())))
        return 0

    @property
    def index(self) -> int:
        for i in range(self.sdl.SDL_NumJoysticks()):
            if self.sdl.SDL_JoystickGetDeviceInstanceID(i) == self.instance_id:
                return i
        raise AssertionError("the virtual device is not attached")

    def axis(self, number: int, value: float) -> None:
        assert self.sdl.SDL_JoystickSetVirtualAxis(self._js, number, round(value * 32767)) == 0

    def button(self, number: int, down: bool) -> None:
        assert self.sdl.SDL_JoystickSetVirtualButton(self._js, number, int(down)) == 0

    def hat(self, number: int, value: int) -> None:
        assert self.sdl.SDL_JoystickSetVirtualHat(self._js, number, value) == 0

    def detach(self) -> None:
        if self.attached:
            index = self.index
            self.sdl.SDL_JoystickClose(self._js)
            self.sdl.SDL_JoystickDetachVirtual(index)
            self.attached = False

    def reattach(self) -> None:
        """Plug the same device (same GUID) in again."""
        sdl = self.sdl
        index = sdl.SDL_JoystickAttachVirtualEx(ctypes.byref(self._desc))
        assert index >= 0, sdl.SDL_GetError()
        self.instance_id = int(sdl.SDL_JoystickGetDeviceInstanceID(index))
        self._js = sdl.SDL_JoystickOpen(index)
        self.attached = True
