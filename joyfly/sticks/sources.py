"""What `--joy` names, opened: SDL devices (`sdl`, `sdl:N`, `sdl:NAME`), `auto` (the default), or anything the js
reader takes (joyfly/sticks/js/reader.py: a js device, a FIFO, raw:, script:, replay:, a recording); and the profile
a source flies with.

`--joy auto` takes the first SDL game controller, else the first SDL joystick, else the first /dev/input/js* on
Linux, and says which it took and why. When SDL cannot be loaded, `auto` says so in one sentence and reads js
devices; `--joy sdl...` then fails with that sentence.

A plain SDL joystick (not a game controller) flies only with a profile that is its own: the user's (calibrate),
a built-in one matched by GUID or name, one named with --profile, or one described in the config's [profile] table.
Anything else is refused before arming with what to do (a joystick's raw axes mean nothing without one: the generic
profile would fly it by guesswork).
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from joyfly.sticks.examples import virtual_joystick_hint
from joyfly.sticks.js.events import JoystickError
from joyfly.sticks.js.seam import js_reader, open_js
from joyfly.sticks.profiles.profile import BUILTIN, ROLES, Profile, apply_overrides, get_profile, load_profile
from joyfly.sticks.profiles.user import find_user_profile
from joyfly.sticks.sdl.api import SdlApi, SdlDevice, SdlUnavailable, sdl_api
from joyfly.sticks.sdl.mappings import SdlMappings, apply_mappings
from joyfly.sticks.sdl.source import LIST_HINT, SDL_PREFIX, SdlSource, choose_device
from joyfly.types import Clock, JoystickSource

AUTO = "auto"
_NOT_OWN = ("generic", "script")  # catch-alls: never "a profile for this joystick"


@dataclass(frozen=True, slots=True)
class Opened:
    source: JoystickSource
    why: str  # which device was chosen and why ("" when the user named a path)


def is_sdl_spec(spec: str) -> bool:
    return spec.lower() == SDL_PREFIX or spec.lower().startswith(SDL_PREFIX + ":")


def _start_sdl(mappings: SdlMappings, loader: Callable[[], SdlApi]) -> SdlApi:
    api = loader()
    apply_mappings(api, mappings)
    return api


def open_source(spec: str, clock: Clock, dev_dir: str = "/dev/input", mappings: SdlMappings | None = None,
                loader: Callable[[], SdlApi] = sdl_api) -> Opened:
    """Open what `--joy spec` names; JoystickError (one sentence) when it cannot."""
    mappings = mappings or SdlMappings()
    if spec.strip().lower() == AUTO:
        return _open_auto(clock, dev_dir, mappings, loader)
    if is_sdl_spec(spec):
        api = _start_sdl(mappings, loader)
        device, reason = choose_device(api.devices(), spec)
        return _sdl_opened(api, device, clock, reason)
    if not mappings.empty and mappings.file is not None:
        _start_sdl(mappings, loader)  # a broken --sdl-mapping is reported whatever --joy says
    return Opened(open_js(spec, clock, dev_dir), "")


def _open_auto(clock: Clock, dev_dir: str, mappings: SdlMappings, loader: Callable[[], SdlApi]) -> Opened:
    try:
        api = _start_sdl(mappings, loader)
    except SdlUnavailable as exc:
        if not sys.platform.startswith("linux"):
            raise
        path = js_reader().default_device(dev_dir)
        why = f"{path}: the first js device ({str(exc).rstrip('.')}; so js devices are read instead)"
        return Opened(open_js(path, clock, dev_dir), why)
    devices = api.devices()
    pads = [d for d in devices if d.is_controller]
    if pads or devices:
        reason = "the first SDL game controller" if pads else "the first SDL joystick (no game controller is here)"
        return _sdl_opened(api, (pads or devices)[0], clock, reason)
    if sys.platform.startswith("linux"):
        try:
            path = js_reader().default_device(dev_dir)
        except JoystickError:
            raise JoystickError(f"No joystick found: SDL sees no controller and there is no {dev_dir}/js*; plug one "
                                f"in and {LIST_HINT}, or fly a virtual one with {virtual_joystick_hint()}.") from None
        return Opened(open_js(path, clock, dev_dir), f"{path}: the first js device (SDL sees no controller)")
    raise JoystickError(f"No joystick found (SDL sees no controller): plug one in and {LIST_HINT}.")


def _sdl_opened(api: SdlApi, device: SdlDevice, clock: Clock, reason: str) -> Opened:
    why = f"sdl:{device.index} \"{device.name}\" ({device.kind}, GUID {device.guid}): {reason}"
    return Opened(SdlSource(api, device, clock, why), why)


# ---------------------------------------------------------------------------------------------------------- profiles


def own_profile(name: str, guid: str) -> Profile | None:
    """A built-in profile for this plain joystick: by its SDL GUID, then by its name (never a catch-all)."""
    for profile in BUILTIN:
        if guid and guid.lower() in (g.lower() for g in profile.guids):
            return profile
    for profile in BUILTIN:
        if profile.name not in _NOT_OWN and profile.matches(name):
            return profile
    return None


def _described(table: Mapping[str, Any]) -> bool:
    """The config's [profile] table names a base profile or maps an axis: the user described the device."""
    inner = table.get("profile", table)
    return isinstance(inner, Mapping) and ("base" in inner or any(role in inner for role in (*ROLES, "throttle")))


def check_profile_choice(name_or_auto: str | None, overrides: Mapping[str, Any] | None) -> None:
    """Refuse an unknown --profile (or `[profile] base`) before any joystick is looked for: it needs no device."""
    table = dict(overrides or {})
    inner = table.get("profile", table)
    name = (name_or_auto or AUTO).strip()
    base = inner.get("base") if isinstance(inner, Mapping) else None
    if name.lower() != AUTO:
        get_profile(name)
    elif base:
        get_profile(str(base))


def pick_profile(source: JoystickSource, name_or_auto: str | None, overrides: Mapping[str, Any] | None) -> Profile:
    """The profile `source` flies with: with --profile auto, the user's own profile for this device (written by
    `joyfly joystick calibrate`, joyfly/sticks/profiles/user.py) first, then profiles.load_profile; a plain SDL
    joystick nothing describes is refused."""
    table = dict(overrides or {})
    name = (name_or_auto or AUTO).strip()
    if name.lower() == AUTO and "base" not in table.get("profile", table):
        mine = find_user_profile(source.name, str(getattr(source, "guid", "")))
        if mine is not None:
            inner = table.get("profile", table)
            return apply_overrides(mine.profile, inner) if inner else mine.profile
    if isinstance(source, SdlSource) and not source.is_controller and name.lower() == AUTO and not _described(table):
        own = own_profile(source.device.name, source.guid)
        if own is None:
            raise JoystickError(
                f"{source.path} \"{source.device.name}\" (GUID {source.guid}) is a joystick SDL does not know as a "
                "game controller and no profile matches it, so joyfly will not guess its axes: calibrate it with "
                f"`joyfly joystick calibrate --joy {source.path}`, give it an SDL mapping with --sdl-mapping, or pick "
                "a profile with --profile.")
        name = own.name
    return load_profile(name, source.name, table)
