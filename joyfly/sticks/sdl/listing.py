"""What `joyfly joystick list` says about SDL's devices: index, name, GUID, game controller or joystick, axes,
buttons and hats, rumble, and the profile `joyfly fly` would fly it with (or why it would refuse it)."""

from __future__ import annotations

from collections.abc import Callable

from joyfly.sticks.js.events import JoystickError
from joyfly.sticks.profiles.profile import load_profile
from joyfly.sticks.profiles.user import find_user_profile
from joyfly.sticks.sdl.api import SdlApi, SdlDevice, SdlUnavailable, sdl_api
from joyfly.sticks.sdl.mappings import SdlMappings, apply_mappings
from joyfly.sticks.sdl.source import GAME_CONTROLLER_TAG
from joyfly.sticks.sources import own_profile


def _profile_text(device: SdlDevice) -> str:
    name = device.name + (GAME_CONTROLLER_TAG if device.is_controller else "")
    mine = find_user_profile(name, device.guid)
    if mine is not None:
        return f"profile: {mine.profile.name}"
    if device.is_controller:
        return f"profile: {load_profile('auto', device.name + GAME_CONTROLLER_TAG).name}"
    own = own_profile(device.name, device.guid)
    if own is not None:
        return f"profile: {own.name}"
    return f"profile: none (joyfly fly refuses it: `joyfly joystick calibrate --joy sdl:{device.index}`)"


def device_line(device: SdlDevice) -> str:
    rumble = "rumble" if device.rumble else "no rumble"
    return (f"sdl:{device.index}  \"{device.name}\"  {device.kind}  GUID {device.guid}  {device.axes} axes, "
            f"{device.buttons} buttons, {device.hats} hats, {rumble}  {_profile_text(device)}")


def sdl_lines(mappings: SdlMappings | None = None, loader: Callable[[], SdlApi] = sdl_api) -> list[str]:
    """One line per SDL device; a single line saying why when SDL cannot be loaded (js devices are listed anyway).
    A broken mapping is a JoystickError for the caller."""
    try:
        api = loader()
    except SdlUnavailable as exc:
        return [f"?  {exc}"]
    apply_mappings(api, mappings or SdlMappings())
    lines = []
    for device in api.devices():
        try:
            lines.append(device_line(api.describe(device)))
        except JoystickError as exc:  # pragma: no cover - a profile problem while describing
            lines.append(f"?  sdl:{device.index} \"{device.name}\": {exc}")
    return lines
