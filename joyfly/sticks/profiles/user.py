"""Profiles the user wrote (`joyfly joystick calibrate` writes them): one TOML file per device in the profile
directory, looked up before the built-in profiles whenever `--profile` is auto.

The directory: $JOYFLY_PROFILES if set, else joyfly/profiles under the user's configuration directory
(%APPDATA% on Windows, $XDG_CONFIG_HOME or ~/.config elsewhere). A file::

    # written by joyfly joystick calibrate
    [device]
    name = "Mystery Stick 3000"          # the device name as joyfly reads it (`joyfly joystick list`)
    guid = "0300...."                     # SDL's GUID; optional (js devices have none)
    [profile]                             # the same keys as a --config file's [profile] table
    arm_hold_s = 1.0
    [profile.forward]
    index = 1
    invert = true
    deadzone = 0.06
    [profile.buttons]
    arm = 7

It applies to a device whose name is the same (any case) and, when both have one, whose GUID is the same.
A file that is not such a profile ends in one sentence naming it.
"""

from __future__ import annotations

import os
import re
import sys
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from joyfly.sticks.profiles.profile import Profile, ProfileError, apply_overrides, read_config
from joyfly.types import Action

ENV_DIR = "JOYFLY_PROFILES"


def profile_dir() -> Path:
    if os.environ.get(ENV_DIR):
        return Path(os.environ[ENV_DIR])
    if sys.platform.startswith("win") and os.environ.get("APPDATA"):
        return Path(os.environ["APPDATA"]) / "joyfly" / "profiles"
    base = os.environ.get("XDG_CONFIG_HOME") or str(Path.home() / ".config")
    return Path(base) / "joyfly" / "profiles"


@dataclass(frozen=True, slots=True)
class UserProfile:
    path: Path
    device_name: str
    guid: str
    profile: Profile

    def fits(self, device_name: str, guid: str) -> bool:
        if self.device_name.strip().lower() != device_name.strip().lower():
            return False
        return not (self.guid and guid) or self.guid.lower() == guid.lower()


_EMPTY = Profile("calibrated", "", (), {}, {})


def parse_user_profile(path: Path, data: Mapping[str, Any]) -> UserProfile:
    device, table = data.get("device"), data.get("profile")
    if not isinstance(device, Mapping) or not isinstance(device.get("name"), str) or not isinstance(table, Mapping):
        raise ProfileError(f"{path} is not a joyfly profile (it needs a [device] table with name and a [profile] "
                           "table): rewrite it with `joyfly joystick calibrate` or remove it.")
    guid = device.get("guid", "")
    profile = apply_overrides(_EMPTY, table)
    name = f"calibrated:{path.stem}"
    return UserProfile(path, device["name"], str(guid),
                       replace(profile, name=name, description=f"written for \"{device['name']}\" ({path})",
                               guids=(str(guid),) if guid else ()))


def load_user_profiles(directory: Path | None = None) -> list[UserProfile]:
    folder = directory or profile_dir()
    if not folder.is_dir():
        return []
    return [parse_user_profile(path, read_config(str(path))) for path in sorted(folder.glob("*.toml"))]


def find_user_profile(device_name: str, guid: str = "", directory: Path | None = None) -> UserProfile | None:
    return next((p for p in load_user_profiles(directory) if p.fits(device_name, guid)), None)


# ---------------------------------------------------------------------------------------------------------- writing


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return f"{value:.3g}"
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    return str(value)


def profile_toml(device_name: str, guid: str, profile: Profile, when: str = "") -> str:
    """The text of a user profile file for `profile` (its axes, buttons and arm hold)."""
    lines = [f"# written by joyfly joystick calibrate{when}; edit it, or calibrate again", "[device]",
             f"name = {_toml_value(device_name)}"]
    if guid:
        lines.append(f"guid = {_toml_value(guid)}")
    lines += ["", "[profile]", f"arm_hold_s = {_toml_value(profile.arm_hold_s)}"]
    for role, axis in profile.axes.items():
        key = "throttle" if role == "throttle_abs" else role
        lines += ["", f"[profile.{key}]", f"index = {axis.index}", f"invert = {_toml_value(axis.invert)}",
                  f"deadzone = {_toml_value(round(axis.deadzone, 3))}"]
    if profile.buttons:
        lines += ["", "[profile.buttons]"]
        lines += [f"{action.value} = {index}" for action, index in profile.buttons.items() if action in Action]
    return "\n".join(lines) + "\n"


def file_name(device_name: str) -> str:
    slug = re.sub(r"[^a-z0-9]+", "-", device_name.lower()).strip("-") or "joystick"
    return f"{slug[:60]}.toml"


def write_user_profile(text: str, device_name: str, directory: Path | None = None) -> Path:
    folder = directory or profile_dir()
    path = folder / file_name(device_name)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    except OSError as exc:
        raise ProfileError(f"Cannot write the profile {path} ({exc.strerror}): set {ENV_DIR} to a directory you can "
                           "write to.") from None
    return path
