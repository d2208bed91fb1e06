"""Can these sticks take off in PX4's Position or Altitude mode? A check at start, before anything is sent.

In POSCTL and ALTCTL only the throttle takes off: PX4 asks for a take-off once the throttle passes 0.3 above its
centre (MANUAL_CONTROL z > 650; FlightTaskManualAltitude::_checkTakeoff), and disarms a vehicle still on the ground
COM_DISARM_PRFLT (10 s) after arming. joyfly arms as soon as the vehicle answers, so a joystick whose throttle never
rises, or a timed joystick (script, recording, raw capture) that pushes it only later, leaves the vehicle on the
ground, and the flight ends with "distance flown 0.0 m" (issue 25.8). A profile with no throttle at all is refused
before this (cli.throttle_problem); this warns about what the profile cannot show.
"""

from __future__ import annotations

from typing import Any

from joyfly.sticks.examples import POSITION_SCRIPT, example_script
from joyfly.sticks.manual import Z_CENTRE, to_manual
from joyfly.sticks.mapping import map_state
from joyfly.sticks.profiles.profile import Profile
from joyfly.sticks.virtual import TimedSource
from joyfly.types import JoyState

WANT_TAKEOFF_THROTTLE = 0.3  # PX4's FlightTaskManualAltitude::_checkTakeoff (z / 500 - 1 above this)
TAKEOFF_Z = round(Z_CENTRE * (1.0 + WANT_TAKEOFF_THROTTLE))  # 650: z must be above it (in float32, 650 is not)
PREFLIGHT_DISARM_S = 10.0  # PX4's COM_DISARM_PRFLT default: disarmed again if still on the ground by then


def first_takeoff_throttle_s(source: TimedSource, profile: Profile) -> float | None:
    """The first time (seconds into the timed source) its throttle, as joyfly would send it, asks PX4 to take off."""
    for step in source.steps:
        cmd = map_state(profile, JoyState(step.t_s, step.axes, step.buttons, step.connected))
        if cmd.connected and to_manual(cmd).z > TAKEOFF_Z:
            return step.t_s
    return None


def takeoff_warning(source: Any, profile: Profile, mode: str) -> str | None:
    """A sentence when these sticks cannot (or likely will not) take off in `mode` (e.g. "Position mode"), else
    None: a timed source that never raises the throttle or raises it after PREFLIGHT_DISARM_S, or a device that
    reports fewer axes than the profile's throttle axis needs."""
    inner = source
    while hasattr(inner, "source"):  # through a --record RecordingSource
        inner = inner.source
    if isinstance(inner, TimedSource):
        return _timed_warning(inner, profile, mode)
    axis = profile.axis("up") or profile.axis("throttle_abs")
    axes = getattr(getattr(inner, "info", None), "axes", 0)  # a js device's JSIOCGAXES (0: unknown, a FIFO)
    if axis is not None and 0 < axes <= axis.index:
        return (f"The joystick {inner.name} reports {axes} axes but the profile {profile.name} takes the throttle "
                f"from axis {axis.index}, so in {mode} the vehicle cannot take off: pick another --profile, or set "
                "[profile.up] index in a --config file.")
    return None


def _timed_warning(source: TimedSource, profile: Profile, mode: str) -> str | None:
    first_s = first_takeoff_throttle_s(source, profile)
    fix = f"see {example_script(POSITION_SCRIPT)} for a script that takes off in this mode"
    if first_s is None:
        return (f"The joystick {source.path} never pushes the throttle (up) above {WANT_TAKEOFF_THROTTLE:g}, so in "
                f"{mode} the vehicle cannot take off (only the throttle takes off there): {fix}.")
    if first_s > PREFLIGHT_DISARM_S:
        return (f"The joystick {source.path} first pushes the throttle up at {first_s:g} s, but joyfly arms as soon "
                f"as the vehicle answers and PX4 disarms a vehicle that has not taken off {PREFLIGHT_DISARM_S:g} s "
                f"after arming (COM_DISARM_PRFLT), so in {mode} the vehicle will likely not take off: {fix}.")
    return None
