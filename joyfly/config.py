"""`joyfly fly` options: defaults, the TOML config file (`--config`), validation, and the session settings.

A config file sets any option in a `[fly]` table (or at the top level), with the option's name as on the command
line (`max-speed` or `max_speed`); the `[profile]` table overrides the joystick profile
(joyfly/sticks/profiles/profile.py).
Command-line options win over the file, the file over the defaults::

    [fly]
    url = "udp://:14540@127.0.0.1:14557"
    joy = "sdl"               # or "auto" (the default), "sdl:1", "sdl:xbox", "/dev/input/js0", "script:FILE"
    sdl-mapping = "gamecontrollerdb.txt"   # extra SDL game-controller mappings (or one mapping line)
    rumble = false            # like --no-rumble
    control = "velocity"      # or "step" (OFFBOARD), "position" or "altitude" (PX4's manual modes)
    max-speed = 3.0
    fence = 8.0
    fence-action = "land"     # or "warn", "hold", "rtl"
    on-exit = "rtl"

    mappings = ["030000005e0400008e02000010010000,My pad,a:b0,b:b1,...,leftx:a0,lefty:a1,..."]

    [profile]
    base = "xbox"
    deadzone = 0.1
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass, fields, replace
from typing import Any

from joyfly.link.transport import UrlError, parse_url
from joyfly.session.core import SessionSettings
from joyfly.session.fence_watch import FENCE_ACTIONS
from joyfly.session.manual_session import MANUAL_CONTROLS
from joyfly.session.manual_session import RATE_HZ as MANUAL_RATE_HZ
from joyfly.sticks.profiles.profile import read_config
from joyfly.sticks.setpoints import Limits
from px4common.clock import SPEED_MAX, SPEED_MIN

DEFAULT_URL = "udp://:14540@127.0.0.1:14557"
CONTROLS = ("velocity", "step", *MANUAL_CONTROLS)
ON_EXIT = ("land", "hold", "rtl")
MIN_RATE_HZ = 10.0  # PX4 needs a setpoint younger than COM_OF_LOSS_T = 1 s; 10 Hz leaves room for lost datagrams


class ConfigError(Exception):
    """A bad option or config file; the message is one sentence saying what to fix."""


@dataclass(frozen=True, slots=True)
class FlyOptions:
    joy: str = "auto"  # the first SDL game controller, else SDL joystick, else /dev/input/js0 (sticks/sources.py)
    url: str = DEFAULT_URL
    profile: str = "auto"
    control: str = "velocity"
    step: float = 2.0  # m per full stick (step control)
    alt: float = 3.0  # m above home, take-off altitude
    max_climb: float = 1.0  # m/s
    max_speed: float = 5.0  # m/s horizontal
    max_yaw_rate: float = 45.0  # deg/s
    fence: float = 5.0  # m half-width of the square around home; 0 disables
    fence_action: str = "land"  # when the vehicle stays outside the fence: warn | hold | rtl | land
    min_alt: float = 0.5  # m above home
    max_alt: float = 10.0  # m above home
    rate: float = 20.0  # Hz setpoint stream (OFFBOARD); --control position/altitude: MANUAL_RATE_HZ unless given
    on_exit: str = "land"
    record: str | None = None
    joy_timeout: float = 5.0  # s
    connect_timeout: float = 15.0  # s
    speed: float = 1.0  # the emulator's speed factor (sitl-emu serve --speed): joyfly's timing follows it
    sdl_mapping: str | None = None  # a gamecontrollerdb.txt or one SDL mapping line (sticks/sdl/mappings.py)
    mappings: tuple[str, ...] = ()  # SDL mapping lines from the config file's `mappings` list
    rumble: bool = True  # rumble pulses on a pad that has them (sticks/rumble.py); --no-rumble
    signing_key: str | None = None  # MAVLink 2 signing key file (px4common/signing_key.py)
    setup_signing: bool = False  # give the vehicle the key with SETUP_SIGNING

    def session_settings(self, **extra: Any) -> SessionSettings:
        limits = Limits(control=self.control, step_m=self.step, max_speed_m_s=self.max_speed,
                        max_climb_m_s=self.max_climb, max_yaw_rate_rad_s=math.radians(self.max_yaw_rate))
        return SessionSettings(alt_m=self.alt, rate_hz=self.rate, on_exit=self.on_exit,
                               joy_timeout_s=self.joy_timeout, connect_timeout_s=self.connect_timeout,
                               fence_m=self.fence, fence_action=self.fence_action, min_alt_m=self.min_alt,
                               max_alt_m=self.max_alt, limits=limits, **extra)


OPTION_NAMES = tuple(f.name for f in fields(FlyOptions))


@dataclass(frozen=True, slots=True)
class Bound:
    lo: float
    hi: float
    unit: str
    why: str = ""


# Every number a user can give, with its range; --alt has one range only: from --min-alt to --max-alt (validate).
BOUNDS: dict[str, Bound] = {
    "step": Bound(0.1, 50.0, "m"),
    "max_climb": Bound(0.1, 8.0, "m/s", " (PX4's MPC_Z_VEL_MAX_UP goes up to 8 m/s)"),
    "max_speed": Bound(0.1, 20.0, "m/s", " (PX4's MPC_XY_VEL_MAX goes up to 20 m/s)"),
    "max_yaw_rate": Bound(0.0, 400.0, "deg/s", " (PX4's MPC_MAN_Y_MAX goes up to 400 deg/s)"),
    "fence": Bound(0.0, 10000.0, "m", " (0 turns the fence off)"),
    "min_alt": Bound(0.0, 1000.0, "m"),
    "max_alt": Bound(0.1, 1000.0, "m"),
    "rate": Bound(MIN_RATE_HZ, 200.0, "Hz", " (PX4 leaves OFFBOARD after 1 s without a setpoint, and takes "
                                            "MANUAL_CONTROL for lost after 0.5 s; it needs no more than 50 Hz)"),
    "joy_timeout": Bound(0.1, 600.0, "s"),
    "connect_timeout": Bound(1.0, 3600.0, "s"),
    "speed": Bound(SPEED_MIN, SPEED_MAX, "times real time", " (the vehicle's sitl-emu serve --speed; 1 for PX4 SITL)"),
}
CHOICES: dict[str, tuple[str, ...]] = {"control": CONTROLS, "on_exit": ON_EXIT, "fence_action": FENCE_ACTIONS}


def load_file(path: str) -> tuple[dict[str, Any], dict[str, Any]]:
    """(fly options, profile table) from a TOML config file."""
    data = read_config(path)
    profile = data.get("profile", {})
    table = data.get("fly", {k: v for k, v in data.items() if k != "profile"})
    if "fly" in data and "mappings" in data and isinstance(table, Mapping):
        table = {**table, "mappings": data["mappings"]}  # `mappings = [...]` may sit beside [fly] too
    if not isinstance(table, Mapping) or not isinstance(profile, Mapping):
        raise ConfigError(f"{path}: [fly] and [profile] must be tables.")
    options: dict[str, Any] = {}
    for key, value in table.items():
        name = key.replace("-", "_")
        if name not in OPTION_NAMES:
            raise ConfigError(f"{path}: unknown option '{key}'; known options: "
                              f"{', '.join(n.replace('_', '-') for n in OPTION_NAMES)}.")
        options[name] = value
    return options, dict(profile)


class _Origins:
    """Names an option as the user wrote it: `--alt 50` on the command line, `FILE: alt = 50` in the config file."""

    def __init__(self, file_options: Mapping[str, Any], cli_options: Mapping[str, Any], source: str | None) -> None:
        self.source = source
        self.from_file = {k for k in file_options if cli_options.get(k) is None}
        self.from_cli = {k for k, v in cli_options.items() if v is not None}

    def says(self, name: str, value: Any) -> str:
        key = name.replace("_", "-")
        if name in self.from_file:
            return f"{self.source or 'the config file'}: {key} = {_toml(value)}"
        return ("" if name in self.from_cli else "the default ") + self.example(name, value)

    def example(self, name: str, value: Any) -> str:
        key = name.replace("_", "-")
        if name in self.from_file:
            return f"{key} = {_toml(value)}"
        return f"--{key} {value:g}" if isinstance(value, float) else f"--{key} {value}"

    def key(self, name: str) -> str:
        key = name.replace("_", "-")
        return key if name in self.from_file else f"--{key}"


def _toml(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return f"{value:g}"
    return json.dumps(value) if isinstance(value, str) else str(value)


def build_options(file_options: Mapping[str, Any], cli_options: Mapping[str, Any],
                  source: str | None = None) -> FlyOptions:
    """Defaults, then the config file (`source`), then the options given on the command line; validated."""
    origins = _Origins(file_options, cli_options, source)
    merged = {**file_options, **{k: v for k, v in cli_options.items() if v is not None}}
    if merged.get("control") in MANUAL_CONTROLS and "rate" not in merged:
        merged["rate"] = MANUAL_RATE_HZ  # QGroundControl's joystick rate
    opts = replace(FlyOptions(), **{k: _coerce(k, v, origins) for k, v in merged.items()})
    validate(opts, origins)
    return opts


def _coerce(name: str, value: Any, origins: _Origins) -> Any:
    defaults = FlyOptions()
    default = getattr(defaults, name)
    if isinstance(default, bool):
        if not isinstance(value, bool):
            raise ConfigError(f"{origins.says(name, value)} is not true or false: write {name.replace('_', '-')} = "
                              "true or false.")
        return value
    if isinstance(default, tuple):
        if not isinstance(value, (list, tuple)) or not all(isinstance(v, str) for v in value):
            raise ConfigError(f"{origins.says(name, value)} is not a list of SDL mapping lines: write "
                              f"{name} = [\"GUID,name,a:b0,...\"].")
        return tuple(value)
    if isinstance(default, float):
        number = _number(value)
        if number is None:
            if name == "alt":  # checked against min-alt and max-alt, once they are known
                within = (f"between min-alt and max-alt ({defaults.min_alt:g} and {defaults.max_alt:g} m unless you "
                          "change them)")
            else:
                bound = BOUNDS[name]
                within = f"from {bound.lo:g} to {bound.hi:g} {bound.unit}"
            raise ConfigError(f"{origins.says(name, value)} is not a number: write a number {within}, for example "
                              f"{origins.example(name, default)}.")
        return number
    if value is not None and not isinstance(value, str):
        example = origins.example(name, default if default is not None else "FILE")
        raise ConfigError(f"{origins.says(name, value)} is not text: write it in quotes, for example {example}.")
    return value


def _number(value: Any) -> float | None:
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        return None
    try:
        number = float(value)
    except ValueError:
        return None
    return number if math.isfinite(number) else None


def validate(o: FlyOptions, origins: _Origins | None = None) -> None:
    """Raise ConfigError naming the first bad option, its range or choices, and what to write instead."""
    origins = origins or _Origins({}, {}, None)
    for name, choices in CHOICES.items():
        value = getattr(o, name)
        if value not in choices:
            raise ConfigError(f"{origins.says(name, value)} is not a choice here: use one of {', '.join(choices)}.")
    for name, bound in BOUNDS.items():
        value = getattr(o, name)
        if not bound.lo <= value <= bound.hi:
            raise ConfigError(f"{origins.says(name, value)} is out of range: use {bound.lo:g} to {bound.hi:g} "
                              f"{bound.unit}{bound.why}.")
    if o.min_alt >= o.max_alt:
        raise ConfigError(f"{origins.says('min_alt', o.min_alt)} must be below {origins.key('max_alt')} "
                          f"({o.max_alt:g} m): lower the one or raise the other.")
    if not o.min_alt <= o.alt <= o.max_alt:
        raise ConfigError(f"{origins.says('alt', o.alt)} is out of range: use {o.min_alt:g} to {o.max_alt:g} m "
                          f"(from {origins.key('min_alt')} to {origins.key('max_alt')}), or move those bounds.")
    try:
        parse_url(o.url)
    except UrlError as err:
        raise ConfigError(f"{origins.says('url', o.url)}: {err.detail}.") from None
