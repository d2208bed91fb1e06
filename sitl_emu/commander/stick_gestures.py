"""What the sticks say beyond flying: the arm/disarm gestures and a pilot moving the sticks to take over.

After src/modules/manual_control/ManualControl.cpp (processStickArming, processInput's stick-movement check),
src/lib/hysteresis and MovingDiff.hpp, evaluated on every manual input sample as manual_control does:
- arm gesture: throttle low (< -0.8) and yaw right (> 0.9), the right stick centred (|roll|, |pitch| < 0.1), held for
  1 s; disarm gesture: the same with yaw left (< -0.9). Each fires once, on the edge (MAN_ARM_GESTURE = 1).
- sticks moving: on some axis the low-passed rate of change (tau 0.05 s) is above MAN_OVERRIDE_SPD (1/s) and the
  last three changes went the same way, so a single jump or held sticks never count.
"""

from __future__ import annotations

from enum import Enum
from typing import Final

from sitl_emu.types import ManualControlSetpoint

GESTURE_HOLD_US: Final = 1_000_000  # ManualControl.cpp: fixed 1 s hysteresis (was COM_RC_ARM_HYST)
MOVE_FILTER_TAU_S: Final = 0.05
MOVE_SAME_SIGN_SAMPLES: Final = 3


class Gesture(Enum):
    ARM = "arm"
    DISARM = "disarm"


def _centred(sp: ManualControlSetpoint) -> bool:
    return abs(sp.pitch) < 0.1 and abs(sp.roll) < 0.1


def gesture_of(sp: ManualControlSetpoint) -> Gesture | None:
    """The gesture the sticks show right now, if any."""
    if sp.throttle < -0.8 and _centred(sp):
        if sp.yaw > 0.9:
            return Gesture.ARM
        if sp.yaw < -0.9:
            return Gesture.DISARM
    return None


class GestureDetector:
    """A gesture held GESTURE_HOLD_US fires once (the hysteresis' rising edge)."""

    def __init__(self) -> None:
        self._pose: Gesture | None = None
        self._since_us = 0
        self._fired = False

    def reset(self) -> None:
        self._pose, self._fired = None, False

    def update(self, now_us: int, sp: ManualControlSetpoint) -> Gesture | None:
        pose = gesture_of(sp)
        if pose is not self._pose:
            self._pose, self._since_us, self._fired = pose, now_us, False
        if pose is None or self._fired or now_us - self._since_us < GESTURE_HOLD_US:
            return None
        self._fired = True
        return pose


class _AxisMotion:
    """MovingDiff for one axis: the low-passed derivative and the run of same-sign changes."""

    __slots__ = ("last", "rate", "same_sign", "sign")

    def __init__(self) -> None:
        self.last: float | None = None
        self.rate = 0.0
        self.same_sign = 0
        self.sign = 0

    def update(self, value: float, dt_s: float) -> None:
        if self.last is not None and dt_s > 0.0:
            diff = value - self.last
            self.rate += dt_s / (MOVE_FILTER_TAU_S + dt_s) * (diff / dt_s - self.rate)
            sign = (diff > 0.0) - (diff < 0.0)
            if sign != 0:
                self.same_sign = self.same_sign + 1 if sign == self.sign else 1
                self.sign = sign
        self.last = value


class StickMotion:
    """sticks_moving: a pilot deliberately moving a stick (MAN_OVERRIDE_SPD, 1/s; negative disables)."""

    def __init__(self) -> None:
        self._axes = [_AxisMotion() for _ in range(4)]
        self._last_us: int | None = None

    def reset(self) -> None:
        self._axes = [_AxisMotion() for _ in range(4)]
        self._last_us = None

    def update(self, now_us: int, sp: ManualControlSetpoint, override_speed: float) -> bool:
        dt_s = 0.0 if self._last_us is None else (now_us - self._last_us) * 1e-6
        self._last_us = now_us
        moving = False
        for axis, value in zip(self._axes, (sp.roll, sp.pitch, sp.yaw, sp.throttle), strict=True):
            axis.update(value, dt_s)
            if abs(axis.rate) > override_speed and axis.same_sign >= MOVE_SAME_SIGN_SAMPLES:
                moving = True
        return moving and override_speed >= 0.0
