"""`joyfly fly` options: defaults, the TOML config file (`--config`), validation, and the session settings.

A config file sets any option in a `[fly]` table (or at the top level), with the option's name as on the command
line (`max-speed` or `max_speed`); the `[profile]` table overrides the joystick profile (joyfly/profiles.py).
Command-line options win over the file, the file over the defaults::

    [fly]
    url = "udp://:14540@127.0.0.1:14557"
    joy = "/dev/input/js0"
    control = "velocity"      # or "step"
    max-speed = 3.0
    fence = 8.0
    on-exit = "rtl"

    [profile]
    base = "xbox"
    deadzone = 0.1
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, fields, replace
from typing import Any

from joyfly.flight_session import SessionSettings
from joyfly.profiles import read_config
from joyfly.setpoints import Limits

DEFAULT_URL = "udp://:14540@127.0.0.1:14557"
CONTROLS = ("velocity", "step")
ON_EXIT = ("land", "hold", "rtl")
MIN_RATE_HZ = 10.0  # PX4 needs a setpoint younger than COM_OF_LOSS_T = 1 s; 10 Hz leaves room for lost datagrams


class ConfigError(Exception):
    """A bad option or config file; the message is one sentence saying what to fix."""


@dataclass(frozen=True, slots=True)
class FlyOptions:
    joy: str = "/dev/input/js0"
    url: str = DEFAULT_URL
    profile: str = "auto"
    control: str = "velocity"
    step: float = 2.0  # m per full stick (step control)
    alt: float = 3.0  # m above home, take-off altitude
    max_climb: float = 1.0  # m/s
    max_speed: float = 5.0  # m/s horizontal
    max_yaw_rate: float = 45.0  # deg/s
    fence: float = 5.0  # m half-width of the square around home; 0 disables
    min_alt: float = 0.5  # m above home
    max_alt: float = 10.0  # m above home
    rate: float = 20.0  # Hz setpoint stream
    on_exit: str = "land"
    record: str | None = None
    joy_timeout: float = 5.0  # s
    connect_timeout: float = 15.0  # s
    speed: float = 1.0  # the emulator's speed factor (sitl-emu serve --speed): joyfly's timing follows it

    def session_settings(self, **extra: Any) -> SessionSettings:
        limits = Limits(control=self.control, step_m=self.step, max_speed_m_s=self.max_speed,
                        max_climb_m_s=self.max_climb, max_yaw_rate_rad_s=math.radians(self.max_yaw_rate))
        return SessionSettings(alt_m=self.alt, rate_hz=self.rate, on_exit=self.on_exit,
                               joy_timeout_s=self.joy_timeout, connect_timeout_s=self.connect_timeout,
                               fence_m=self.fence, min_alt_m=self.min_alt, max_alt_m=self.max_alt, limits=limits,
                               **extra)


OPTION_NAMES = tuple(f.name for f in fields(FlyOptions))


def load_file(path: str) -> tuple[dict[str, Any], dict[str, Any]]:
    """(fly options, profile table) from a TOML config file."""
    data = read_config(path)
    profile = data.get("profile", {})
    table = data.get("fly", {k: v for k, v in data.items() if k != "profile"})
    if not isinstance(table, Mapping) or not isinstance(profile, Mapping):
        raise ConfigError(f"{path}: [fly] and [profile] must be tables.")
    options: dict[str, Any] = {}
    for key, value in table.items():
        name = key.replace("-", "_")
        if name not in OPTION_NAMES:
            raise ConfigError(f"{path}: unknown option '{key}'; known options: {', '.join(OPTION_NAMES)}.")
        options[name] = value
    return options, dict(profile)


def build_options(file_options: Mapping[str, Any], cli_options: Mapping[str, Any]) -> FlyOptions:
    """Defaults, then the config file, then the options given on the command line; validated."""
    opts = FlyOptions()
    merged = {**file_options, **{k: v for k, v in cli_options.items() if v is not None}}
    try:
        opts = replace(opts, **{k: _coerce(k, v) for k, v in merged.items()})
    except (TypeError, ValueError):
        raise ConfigError(f"Bad option value in {merged}: numbers must be numbers.") from None
    validate(opts)
    return opts


def _coerce(name: str, value: Any) -> Any:
    default = getattr(FlyOptions(), name)
    if isinstance(default, float):
        if isinstance(value, bool) or not isinstance(value, (int, float, str)):
            raise ConfigError(f"Option {name.replace('_', '-')} must be a number, not {value!r}.")
        try:
            return float(value)
        except ValueError:
            raise ConfigError(f"Option {name.replace('_', '-')} must be a number, not {value!r}.") from None
    return None if value is None else str(value)


def validate(o: FlyOptions) -> None:
    checks = [
        (o.control in CONTROLS, f"--control must be one of {', '.join(CONTROLS)}, not '{o.control}'."),
        (o.on_exit in ON_EXIT, f"--on-exit must be one of {', '.join(ON_EXIT)}, not '{o.on_exit}'."),
        (o.rate >= MIN_RATE_HZ, f"--rate must be at least {MIN_RATE_HZ:g} Hz (PX4 drops OFFBOARD after 1 s "
                                f"without a setpoint), not {o.rate:g}."),
        (o.rate <= 200, f"--rate {o.rate:g} Hz is more than PX4 needs: use 10-50 Hz."),
        (o.fence >= 0, "--fence must be 0 (off) or a positive half-width in metres."),
        (0 <= o.min_alt < o.max_alt, f"--min-alt ({o.min_alt:g}) must be below --max-alt ({o.max_alt:g})."),
        (o.min_alt <= o.alt <= o.max_alt, f"--alt {o.alt:g} m must lie between --min-alt and --max-alt."),
        (o.max_speed > 0 and o.max_climb > 0 and o.max_yaw_rate >= 0,
         "--max-speed, --max-climb must be positive and --max-yaw-rate not negative."),
        (o.step > 0, "--step must be positive."),
        (0.1 <= o.speed <= 20, "--speed must be between 0.1 and 20 (the emulator's --speed)."),
        (o.joy_timeout > 0 and o.connect_timeout > 0, "--joy-timeout and the connect timeout must be positive."),
    ]
    for ok, message in checks:
        if not ok:
            raise ConfigError(message)
