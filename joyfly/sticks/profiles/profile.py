"""Controller profiles: which js axis and button does what, per controller, matched by the device name.

Every gamepad profile flies "mode 2": left stick Y = up/down (a centred throttle), left stick X = yaw, right stick
Y = forward, right stick X = right. Whatever the controller's raw signs (on js, up on a stick is negative), a profile
turns them into the flying convention of joyfly.types.StickCommand: stick forward flies north (+forward), stick
right flies east (+right). Triggers rest at -32767 on js, so no built-in profile maps a trigger to a flying axis.

Buttons (gamepads): arm/disarm = Start/Options/Menu held 1 s, takeoff = Y/Triangle, land = A/Cross,
return = B/Circle, hold = X/Square, offboard (re)enter = Back/Share/View; no deadman unless configured.

Overrides come from the `[profile]` table of the config file and merge over the built-in profile::

    [profile]
    base = "xbox"          # used when --profile is auto; default: matched by the device name
    deadzone = 0.08        # every axis
    expo = 0.3             # every centred stick axis
    arm_hold_s = 1.0
    [profile.forward]      # per axis: forward, right, up, yaw, throttle_abs; index -1 unmaps it
    index = 4
    invert = true
    deadzone = 0.1
    expo = 0.2
    scale = 0.8
    [profile.buttons]      # arm, takeoff, land, return, hold, offboard, deadman; -1 unbinds
    deadman = 4
"""

from __future__ import annotations

import fnmatch
import os
import platform
import sys
from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

from joyfly.sticks.js.events import AXIS_MAX, JoystickError
from joyfly.types import Action, JoyState

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

STICK_ROLES = ("forward", "right", "up", "yaw")
ROLES = (*STICK_ROLES, "throttle_abs")
AXIS_KEYS = ("index", "invert", "deadzone", "expo", "scale")
DEFAULT_DEADZONE = 0.05  # ROS joy's default, rescaled so the output still reaches +-1


class ProfileError(JoystickError):
    """A profile name or override a user can fix."""


@dataclass(frozen=True, slots=True)
class AxisMap:
    """One js axis feeding one role: raw/32767, inverted, deadzone (rescaled), expo, then scaled."""

    index: int
    invert: bool = False
    deadzone: float = DEFAULT_DEADZONE
    expo: float = 0.0
    scale: float = 1.0


@dataclass(frozen=True, slots=True)
class Profile:
    """A controller's layout: the device names (and SDL GUIDs) it fits, which axis flies which role, which button
    does which action, and how long the arm button is held."""

    name: str
    description: str
    match: tuple[str, ...]  # fnmatch patterns on the lower-cased js device name
    axes: Mapping[str, AxisMap]  # role -> axis (roles: ROLES)
    buttons: Mapping[Action, int]  # action -> js button index
    arm_hold_s: float = 1.0
    kernel_before: tuple[int, int] | None = None  # only auto-matched on kernels older than this (old hid-sony)
    notes: str = ""
    guids: tuple[str, ...] = ()  # SDL joystick GUIDs it is for (a plain SDL joystick is matched by GUID, then name)

    def axis(self, role: str) -> AxisMap | None:
        return self.axes.get(role)

    def button(self, action: Action) -> int | None:
        return self.buttons.get(action)

    def matches(self, device_name: str) -> bool:
        name = device_name.lower().strip()
        return any(fnmatch.fnmatchcase(name, pattern) for pattern in self.match)


# ---------------------------------------------------------------------------------------------------------- built-in


def _mode2(lx: int, ly: int, rx: int, ry: int, deadzone: float = DEFAULT_DEADZONE) -> dict[str, AxisMap]:
    """Mode-2 gamepad sticks; js Y axes are negative when pushed up, so forward and up are inverted."""
    return {
        "forward": AxisMap(ry, invert=True, deadzone=deadzone),
        "right": AxisMap(rx, deadzone=deadzone),
        "up": AxisMap(ly, invert=True, deadzone=deadzone),
        "yaw": AxisMap(lx, deadzone=deadzone),
    }


def _buttons(arm: int, takeoff: int, land: int, ret: int, hold: int, offboard: int) -> dict[Action, int]:
    return {Action.ARM: arm, Action.TAKEOFF: takeoff, Action.LAND: land, Action.RETURN: ret, Action.HOLD: hold,
            Action.OFFBOARD: offboard}


# xpad: axes 0 LX, 1 LY, 2 LT, 3 RX, 4 RY, 5 RT; buttons 0 A, 1 B, 2 X, 3 Y, 4 LB, 5 RB, 6 Back, 7 Start, 8 Guide
_XPAD_AXES = _mode2(lx=0, ly=1, rx=3, ry=4)
_XPAD_BUTTONS = _buttons(arm=7, takeoff=3, land=0, ret=1, hold=2, offboard=6)

BUILTIN: tuple[Profile, ...] = (
    Profile("script", "joyfly virtual script joystick (values already in the flying convention)", ("joyfly script",),
            {role: AxisMap(i, deadzone=0.0) for i, role in enumerate(STICK_ROLES)},
            {**_buttons(arm=0, takeoff=1, land=2, ret=3, hold=4, offboard=5)}),
    # SDL's standard game-controller layout (joyfly/sticks/sdl/api.py): axes 0 LX, 1 LY, 2 RX, 3 RY, 4 LT, 5 RT;
    # buttons 0 A, 1 B, 2 X, 3 Y, 4 Back, 5 Guide, 6 Start. Any pad SDL's database (or a mapping) knows flies with it.
    Profile("sdl-gamecontroller", "any game controller read through SDL, in SDL's standard layout",
            ("*(sdl game controller)",), _mode2(lx=0, ly=1, rx=2, ry=3),
            _buttons(arm=6, takeoff=3, land=0, ret=1, hold=2, offboard=4),
            notes="triggers (axes 4, 5) rest at 0 and are not mapped"),
    Profile("xbox", "Xbox 360 / Xbox One / Series pads on the xpad driver",
            ("*x-box*", "*xbox*", "*xinput*"), _XPAD_AXES, _XPAD_BUTTONS,
            notes="triggers (axes 2, 5) rest at -32767 and are not mapped"),
    Profile("logitech-x", "Logitech F310/F710 with the switch on X (xpad: same layout as Xbox 360)",
            ("logitech gamepad f310*", "logitech gamepad f710*", "logitech gamepad*"), _XPAD_AXES, _XPAD_BUTTONS),
    # hid-playstation: axes 0 LX, 1 LY, 2 L2, 3 RX, 4 RY, 5 R2; buttons 0 Cross, 1 Circle, 2 Triangle, 3 Square,
    # 4 L1, 5 R1, 6 L2, 7 R2, 8 Share/Create, 9 Options, 10 PS, 11 L3, 12 R3
    Profile("dualshock-old", "DualShock 4 on the old hid-sony driver (kernels before 4.10)",
            ("sony*wireless controller", "wireless controller", "*dualshock*"),
            _mode2(lx=0, ly=1, rx=2, ry=5),  # old order: 0 LX, 1 LY, 2 RX, 3 L2, 4 R2, 5 RY
            _buttons(arm=9, takeoff=3, land=1, ret=2, hold=0, offboard=8),  # 0 Square, 1 Cross, 2 Circle, 3 Triangle
            kernel_before=(4, 10), notes="pick it with --profile dualshock-old when the right stick reads as L2"),
    Profile("dualshock", "DualShock 4 / DualSense on hid-playstation (and hid-sony on kernels from 4.10)",
            ("sony*", "*dualsense*", "wireless controller", "*dualshock*", "*playstation*"),
            _mode2(lx=0, ly=1, rx=3, ry=4), _buttons(arm=9, takeoff=2, land=0, ret=1, hold=3, offboard=8),
            notes="L2/R2 (axes 2, 5) rest at -32767 and are not mapped"),
    # hid-generic "Dual Action": axes 0 LX, 1 LY, 2 RX, 3 RY, 4/5 hat; buttons 0 X, 1 A, 2 B, 3 Y, 4 LB, 5 RB,
    # 6 LT, 7 RT, 8 Back, 9 Start, 10 LS, 11 RS (digital triggers)
    Profile("logitech-d", "Logitech F310/F710 with the switch on D (Dual Action / Cordless RumblePad 2)",
            ("*dual action*", "*rumblepad 2*"), _mode2(lx=0, ly=1, rx=2, ry=3),
            _buttons(arm=9, takeoff=3, land=1, ret=2, hold=0, offboard=8)),
    # EdgeTX/OpenTX USB joystick, AETR: 0 Ail, 1 Ele, 2 Thr (non-centring), 3 Rud; the radio's mixer sets the signs
    # (channel +100% = js +32767 with the default mixer: stick forward/right positive) and applies its own deadbands.
    Profile("radio", "EdgeTX/OpenTX radio in USB joystick mode, mode 2, AETR channel order",
            ("edgetx*", "opentx*", "frsky*", "radiomaster*", "*taranis*"),
            {"right": AxisMap(0, deadzone=0.02), "forward": AxisMap(1, deadzone=0.02),
             "throttle_abs": AxisMap(2, deadzone=0.0), "yaw": AxisMap(3, deadzone=0.02)},
            _buttons(arm=0, takeoff=1, land=2, ret=3, hold=4, offboard=5),
            notes="buttons are CH9..CH14 set as switches; invert an axis in [profile.<role>] if it flies backwards"),
    Profile("generic", "any other joystick: axis 1 forward (pushed up), axis 0 right; Xbox-like buttons", ("*",),
            {"forward": AxisMap(1, invert=True), "right": AxisMap(0)}, _XPAD_BUTTONS),
)
_BY_NAME = {p.name: p for p in BUILTIN}
ALIASES = {"xbox360": "xbox", "xboxone": "xbox", "xpad": "xbox", "f310": "logitech-x", "f710": "logitech-x",
           "ds4": "dualshock", "ps4": "dualshock", "ps5": "dualshock", "dualsense": "dualshock",
           "hid-sony": "dualshock-old", "sdl": "sdl-gamecontroller", "edgetx": "radio", "opentx": "radio",
           "taranis": "radio"}


def profile_names() -> list[str]:
    return [p.name for p in BUILTIN]


def kernel_version(release: str | None = None) -> tuple[int, int]:
    text = release if release is not None else platform.release()
    parts = [int("".join(ch for ch in part if ch.isdigit()) or 0) for part in text.split(".")[:2]]
    major, minor = [*parts, 0, 0][:2]
    return major, minor


def match_profile(device_name: str, kernel_release: str | None = None) -> Profile:
    """The first built-in profile whose pattern fits the device name (the generic one always does)."""
    kernel = kernel_version(kernel_release)
    for profile in BUILTIN:
        if profile.kernel_before is not None and kernel >= profile.kernel_before:
            continue
        if profile.matches(device_name):
            return profile
    return _BY_NAME["generic"]


def get_profile(name: str) -> Profile:
    key = ALIASES.get(name.lower(), name.lower())
    if key not in _BY_NAME:
        raise ProfileError(f"Unknown profile '{name}': choose auto or one of {', '.join(profile_names())}.")
    return _BY_NAME[key]


def load_profile(name_or_auto: str | None, device_name: str, overrides: Mapping[str, Any] | None = None,
                 kernel_release: str | None = None) -> Profile:
    """The profile to fly with: by name, or matched by device name ("auto"), with the `[profile]` table merged in.

    `overrides` is the `[profile]` table (a whole config dict holding a "profile" key is accepted too).
    """
    table = dict(overrides or {})
    if isinstance(table.get("profile"), Mapping):
        table = dict(table["profile"])
    name = (name_or_auto or "auto").strip()
    base_name = table.pop("base", None) if name.lower() == "auto" else None
    table.pop("base", None)
    if name.lower() != "auto":
        profile = get_profile(name)
    elif base_name:
        profile = get_profile(str(base_name))
    else:
        profile = match_profile(device_name, kernel_release)
    return apply_overrides(profile, table) if table else profile


# ---------------------------------------------------------------------------------------------------------- overrides


def _number(where: str, key: str, value: Any, lo: float, hi: float) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not lo <= value <= hi:
        raise ProfileError(f"{where}.{key} = {value!r} is not a number in {lo:g}..{hi:g}: fix the config file.")
    return float(value)


def _index(where: str, value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < -1:
        raise ProfileError(f"{where}.index = {value!r} is not an axis number (-1 unmaps it): fix the config file.")
    return value


def _invert(where: str, value: Any) -> bool:
    if not isinstance(value, bool):
        raise ProfileError(f"{where}.invert = {value!r} is not true/false: fix the config file.")
    return value


def _axis_override(where: str, base: AxisMap | None, table: Mapping[str, Any]) -> AxisMap:
    """One `[profile.<role>]` table merged over that role's axis (already carrying the common deadzone/expo)."""
    unknown = set(table) - set(AXIS_KEYS)
    if unknown:
        raise ProfileError(f"Unknown key '{sorted(unknown)[0]}' in [{where}]: use {', '.join(AXIS_KEYS)}.")
    if base is None:
        raise ProfileError(f"[{where}] maps no axis yet: give it an index.")
    axis = base
    return AxisMap(
        index=_index(where, table["index"]) if "index" in table else axis.index,
        invert=_invert(where, table["invert"]) if "invert" in table else axis.invert,
        deadzone=_number(where, "deadzone", table["deadzone"], 0.0, 0.9) if "deadzone" in table else axis.deadzone,
        expo=_number(where, "expo", table["expo"], 0.0, 1.0) if "expo" in table else axis.expo,
        scale=_number(where, "scale", table["scale"], 0.0, 1.0) if "scale" in table else axis.scale,
    )


def _button_overrides(buttons: dict[Action, int], table: Mapping[str, Any]) -> dict[Action, int]:
    names = {a.value: a for a in Action}
    names["rtl"] = Action.RETURN
    for key, value in table.items():
        if key not in names:
            choices = ", ".join(a.value for a in Action)
            raise ProfileError(f"Unknown button action '{key}' in [profile.buttons]: use {choices}.")
        if isinstance(value, bool) or not isinstance(value, int) or value < -1:
            raise ProfileError(f"profile.buttons.{key} = {value!r} is not a button number (-1 unbinds it): fix that.")
        if value < 0:
            buttons.pop(names[key], None)
        else:
            buttons[names[key]] = value
    return buttons


def _with_common(axis: AxisMap, role: str, table: Mapping[str, Any]) -> AxisMap:
    """The `[profile]`-wide deadzone (every axis) and expo (centred sticks only) applied to one axis."""
    if "deadzone" in table:
        axis = replace(axis, deadzone=_number("profile", "deadzone", table["deadzone"], 0.0, 0.9))
    if "expo" in table and role in STICK_ROLES:
        axis = replace(axis, expo=_number("profile", "expo", table["expo"], 0.0, 1.0))
    return axis


def apply_overrides(profile: Profile, table: Mapping[str, Any]) -> Profile:
    """Merge a `[profile]` table over a profile; raises ProfileError (one sentence) on a mistake."""
    known = {"deadzone", "expo", "arm_hold_s", "buttons", "throttle", *ROLES}
    unknown = set(table) - known
    if unknown:
        raise ProfileError(f"Unknown key '{sorted(unknown)[0]}' in [profile]: use {', '.join(sorted(known))}.")
    axes = {role: _with_common(ax, role, table) for role, ax in profile.axes.items()}
    for key in (*ROLES, "throttle"):
        sub = table.get(key)
        if sub is None:
            continue
        role = "throttle_abs" if key == "throttle" else key
        if not isinstance(sub, Mapping):
            raise ProfileError(f"profile.{key} must be a table such as [profile.{key}] with index = N: fix the config.")
        fresh = _with_common(AxisMap(0), role, table) if role not in axes and "index" in sub else None
        axis = _axis_override(f"profile.{key}", axes.get(role, fresh), sub)
        if axis.index < 0:
            axes.pop(role, None)
        else:
            axes[role] = axis
    button_table = table.get("buttons", {})
    if not isinstance(button_table, Mapping):
        raise ProfileError("profile.buttons must be a table such as [profile.buttons] with land = 3: fix the config.")
    buttons = _button_overrides(dict(profile.buttons), button_table)
    hold = _number("profile", "arm_hold_s", table["arm_hold_s"], 0, 10) if "arm_hold_s" in table else profile.arm_hold_s
    return replace(profile, name=f"{profile.name}+config", axes=axes, buttons=buttons, arm_hold_s=hold)


def read_config(path: str) -> dict[str, Any]:
    """A TOML config file as a dict (tomllib, or tomli on Python 3.10); errors as one sentence."""
    try:
        with open(path, "rb") as fh:
            return tomllib.load(fh)
    except FileNotFoundError:
        raise ProfileError(f"No config file at {path}: check the --config path.") from None
    except tomllib.TOMLDecodeError as exc:
        raise ProfileError(f"{path} is not valid TOML ({exc}): fix that line.") from None
    except UnicodeDecodeError:
        raise ProfileError(f"{path} is not a text file (TOML is UTF-8 text): check the --config path.") from None
    except OSError as exc:
        raise ProfileError(f"Cannot read {path} ({os.strerror(exc.errno or 0)}): check its permissions.") from None


# ---------------------------------------------------------------------------------------------------------- checks


def rest_problems(profile: Profile, state: JoyState) -> list[str]:
    """Sentences for centred stick roles whose axis is far off centre: untouched sticks should read ~0.

    A mapped axis resting at full deflection is a trigger or the wrong profile (e.g. an old hid-sony DS4 layout),
    and would fly the vehicle with nobody touching the controller. Call it on the first state, before arming.
    """
    problems = []
    for role in STICK_ROLES:
        axis = profile.axis(role)
        if axis is None or axis.index >= len(state.axes):
            continue
        raw = state.axes[axis.index]
        if abs(raw) > AXIS_MAX // 2:
            problems.append(
                f"Axis {axis.index} ({role}) reads {100 * raw / AXIS_MAX:+.0f}% with the sticks untouched: centre the "
                f"sticks, or pick the right profile with --profile (now {profile.name}) or set [profile.{role}] index."
            )
    return problems
