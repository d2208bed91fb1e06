"""Joysticks and game controllers read through SDL2, as QGroundControl, MAVProxy and ROS 2's joy do: `--joy sdl`
(the first game controller), `--joy sdl:N` (SDL's device index), `--joy sdl:NAME` (a case-insensitive part of the
name). `SdlSource` meets joyfly.types.JoystickSource; the SDL calls go through joyfly/sticks/sdl/api.py.

A game controller (SDL's database or a user mapping knows it) reads in SDL's standard layout, which the one
built-in profile `sdl-gamecontroller` flies; its source name ends in GAME_CONTROLLER_TAG, so a --record recording
of it replays through the same profile. A plain joystick reads its raw axes (hats as two axes each, as js does).

Hot-plug: when the device goes away the source reports connected False (the session's joystick-loss path: hold,
then land after --joy-timeout); when a device with the same GUID comes back it is opened again and flies on; a
device with another GUID is never taken: joyfly says it ignores it and keeps waiting for its own.

The event pump runs in poll(), on the thread that polls; poll() waits in steps of POLL_STEP_S for input, so a
stick change reaches the session within about a millisecond.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Sequence

from joyfly.sticks.js.events import DeviceVanishedError, JoystickError, NoDeviceError
from joyfly.sticks.sdl.api import Hotplug, Opened, SdlApi, SdlDevice
from joyfly.types import Clock, JoyState

log = logging.getLogger(__name__)

SDL_PREFIX = "sdl"
GAME_CONTROLLER_TAG = " (SDL game controller)"
POLL_STEP_S = 0.001
RESCAN_S = 0.5  # while the device is away, look for it among the devices present this often
LIST_HINT = "see what is connected with `joyfly joystick list`"


def describe_devices(devices: Sequence[SdlDevice]) -> str:
    return ", ".join(f"sdl:{d.index} \"{d.name}\" ({d.kind})" for d in devices) or "nothing"


def choose_device(devices: Sequence[SdlDevice], spec: str) -> tuple[SdlDevice, str]:
    """The device `--joy spec` names (sdl, sdl:N, sdl:NAME) and why it was chosen; NoDeviceError (one sentence)."""
    _, _, want = spec.partition(":")
    want = want.strip()
    seen = (f"SDL sees {describe_devices(devices)}" if devices else "SDL sees no joystick at all")
    if not want:
        pads = [d for d in devices if d.is_controller]
        if pads:
            return pads[0], "the first SDL game controller"
        raise NoDeviceError(f"No game controller is connected ({seen}): plug one in, or pick a joystick with "
                            f"--joy sdl:N; {LIST_HINT}.")
    if want.isdigit():
        index = int(want)
        for d in devices:
            if d.index == index:
                return d, f"SDL device {index}"
        raise NoDeviceError(f"There is no SDL device {index}: {seen}; {LIST_HINT}.")
    for d in devices:
        if want.lower() in d.name.lower():
            return d, f"the first SDL device whose name contains \"{want}\""
    raise NoDeviceError(f"No SDL device's name contains \"{want}\": {seen}; {LIST_HINT}.")


class SdlSource:
    """One SDL device, read as a JoyState (see joyfly/sticks/sdl/api.py for the layout)."""

    def __init__(self, api: SdlApi, device: SdlDevice, clock: Clock, why: str = "",
                 sleep: Callable[[float], None] = time.sleep,
                 monotonic: Callable[[], float] = time.monotonic) -> None:
        self.api = api
        self.device = device
        self.clock = clock
        self.why = why
        self.guid = device.guid
        self.is_controller = device.is_controller
        self.name = device.name + (GAME_CONTROLLER_TAG if device.is_controller else "")
        self.path = f"sdl:{device.index}"
        self.last_error: JoystickError | None = None
        self._sleep, self._monotonic = sleep, monotonic
        self._ignored: set[str] = set()
        self._next_scan_s = 0.0
        self._closed = False
        self.news: list[str] = []  # what the pilot should hear about the device (taken by the face: joyfly/rumble.py)
        opened = api.open(device.index, device.is_controller)
        if opened is None:
            raise NoDeviceError(f"SDL could not open {self.path} \"{device.name}\" ({api.error()}): {LIST_HINT}.")
        self._opened: Opened | None = opened
        self._axes, self._buttons = api.read(opened)
        self.has_rumble = api.has_rumble(opened)

    @property
    def connected(self) -> bool:
        return self._opened is not None

    def poll(self, timeout_s: float) -> JoyState:
        """Pump SDL's events and return the state, waiting (in wall seconds) at most timeout_s for a change."""
        deadline = self._monotonic() + max(0.0, timeout_s)
        while True:
            changed = self._update()
            left = deadline - self._monotonic()
            if changed or left <= 0.0:
                return self.state()
            self._sleep(min(POLL_STEP_S, left))

    def state(self) -> JoyState:
        return JoyState(self.clock.now(), self._axes, self._buttons, self.connected)

    def rumble(self, low: float, high: float, duration_ms: int) -> bool:
        """A rumble pulse (motor strengths 0..1) when the device has rumble and is here; silently nothing else."""
        if self._opened is None or not self.has_rumble:
            return False
        return self.api.rumble(self._opened, low, high, duration_ms)

    def close(self) -> None:
        self._closed = True  # never reopened by a later poll
        if self._opened is not None:
            self.api.close(self._opened)
            self._opened = None

    # -- internals --------------------------------------------------------------------------------------------------

    def _update(self) -> bool:
        """One pump: act on hot-plug, re-read on input; True when the state changed."""
        if self._closed:
            return False
        plugs, moved = self.api.pump()
        was = self.connected
        for kind, which in plugs:
            if kind is Hotplug.REMOVED and self._opened is not None and which == self._opened.instance_id:
                self._lost()
            elif kind is Hotplug.ADDED and self._opened is None:
                self._maybe_back(which)
        if self._opened is not None and not self.api.attached(self._opened):
            self._lost()
        if self._opened is None and self._monotonic() >= self._next_scan_s:
            self._scan()
        if self._opened is None:
            return was  # it just went away: a change
        if was and not moved:
            return False
        before = (self._axes, self._buttons)
        self._axes, self._buttons = self.api.read(self._opened)
        return (self._axes, self._buttons) != before or not was  # moved, or just came back

    def _lost(self) -> None:
        self._next_scan_s = self._monotonic() + RESCAN_S
        if self._opened is not None:
            self.api.close(self._opened)
            self._opened = None
        self.last_error = DeviceVanishedError(f"The joystick \"{self.device.name}\" vanished (unplugged?): plug it "
                                              "back in and joyfly takes it again.")
        log.warning("%s", self.last_error)

    def _scan(self) -> None:
        """Look for our GUID among the devices present (an ADDED event someone else pumped away is not missed)."""
        self._next_scan_s = self._monotonic() + RESCAN_S
        for device in self.api.devices_now():
            if device.guid == self.guid:
                self._maybe_back(device.index)
                return

    def _maybe_back(self, index: int) -> None:
        device = self.api.device(index)
        if device.guid != self.guid:
            if device.guid not in self._ignored:
                self._ignored.add(device.guid)
                self.news.append(f"Ignoring \"{device.name}\" (GUID {device.guid}), plugged in while joyfly waits "
                                 f"for \"{self.device.name}\" (GUID {self.guid}): joyfly never flies another "
                                 "controller on its own; plug that one back in, or restart joyfly to fly this one.")
                log.warning("%s", self.news[-1])
            return
        opened = self.api.open(index, self.is_controller)
        if opened is None:
            return
        self._opened, self.device = opened, device
        self._axes, self._buttons = self.api.read(opened)
        self.last_error = None
        log.info("joystick \"%s\" is back as sdl:%d", device.name, index)
