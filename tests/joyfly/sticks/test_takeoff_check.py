"""The start-up check of --control position/altitude (issue 25.8): sticks that cannot take off are said at once."""

from __future__ import annotations

from dataclasses import dataclass

from support.joyfly_sim import SimClock

from joyfly.sticks.profiles.profile import load_profile
from joyfly.sticks.takeoff_check import first_takeoff_throttle_s, takeoff_warning
from joyfly.sticks.virtual import SCRIPT_NAME, ScriptSource


def script(text: str) -> ScriptSource:
    return ScriptSource.from_text(text, SimClock(), "flight.txt")


PROFILE = load_profile("auto", SCRIPT_NAME, None)


def test_a_script_that_pushes_the_throttle_early_passes() -> None:
    src = script("5 up=1\n+3 up=0\n")
    assert first_takeoff_throttle_s(src, PROFILE) == 5.0 and takeoff_warning(src, PROFILE, "Position mode") is None


def test_a_script_without_throttle_cannot_take_off() -> None:
    warning = takeoff_warning(script("8 forward=0.4\n+2 up=0.3\n+3 end\n"), PROFILE, "Altitude mode")  # 0.3: not above
    assert warning is not None and warning.startswith("The joystick flight.txt never pushes the throttle (up) above")
    assert "in Altitude mode the vehicle cannot take off" in warning and "joystick_script_position.txt" in warning


def test_a_throttle_after_px4s_preflight_disarm_will_likely_not_take_off() -> None:
    warning = takeoff_warning(script("20 up=0.5\n"), PROFILE, "Position mode")
    assert warning is not None and "first pushes the throttle up at 20 s" in warning and "COM_DISARM_PRFLT" in warning


@dataclass
class Info:
    axes: int


@dataclass
class Device:
    name: str
    info: Info


def test_a_device_without_the_profiles_throttle_axis_cannot_take_off() -> None:
    xbox = load_profile("xbox", "Microsoft X-Box 360 pad", None)
    up = xbox.axis("up")
    assert up is not None
    warning = takeoff_warning(Device("pad", Info(axes=up.index)), xbox, "Position mode")
    assert warning is not None and f"reports {up.index} axes" in warning and f"from axis {up.index}" in warning
    assert takeoff_warning(Device("pad", Info(axes=up.index + 1)), xbox, "Position mode") is None
    assert takeoff_warning(Device("fifo", Info(axes=0)), xbox, "Position mode") is None  # a FIFO: counts unknown
