"""From sticks to setpoints in the manual modes, after PX4's stick libraries.

- `stick_expo`: src/lib/sticks/Sticks.cpp getXExpo: the deadzone MAN_DEADZONE, then the expo 0.6 (PX4 fixed it when
  it removed MPC_XY_MAN_EXPO, MPC_Z_MAN_EXPO and MPC_YAW_EXPO, whose default it was).
- `StickYaw`: src/lib/stick_yaw/StickYaw.cpp: the yaw stick commands a yaw rate (MPC_MAN_Y_MAX, filtered with
  MPC_MAN_Y_TAU); the heading locks once the rate has died away.
- `StickAccelerationXY`: flight_mode_manager/tasks/Utility/StickAccelerationXY.cpp (Position mode, MPC_POS_MODE 4):
  the sticks command an acceleration, a virtual drag brakes (harder with the sticks centred), the velocity setpoint
  integrates it, and the position locks when it reaches zero.
- `stick_tilt_acceleration`: StickTiltXY.cpp (Altitude mode): the sticks command a tilt, up to MPC_MAN_TILT_MAX.
Vectors are (north, east); sticks are (forward, right) in the heading frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final

from px4common.manual_defaults import STICK_EXPO
from sitl_emu.control.qmath import constrain, isfinite

FLT_EPSILON: Final = 1.1920929e-07
GRAVITY: Final = 9.80665
NAN: Final = math.nan
Vec2 = tuple[float, float]


def deadzone(value: float, zone: float) -> float:
    """math::deadzone: 0 within +-zone, then rescaled so that full stick stays 1."""
    value, zone = constrain(value, -1.0, 1.0), constrain(zone, 0.0, 0.99)
    if abs(value) <= zone:
        return 0.0
    return (value - math.copysign(zone, value)) / (1.0 - zone)


def expo(value: float, e: float) -> float:
    """math::expo: (1 - e) v + e v^3."""
    value = constrain(value, -1.0, 1.0)
    return (1.0 - e) * value + e * value * value * value


def stick_expo(value: float, zone: float) -> float:
    return expo(deadzone(value, zone), STICK_EXPO)


def unit_limited(v: Vec2) -> Vec2:
    """Sticks::limitStickUnitLengthXY: a diagonal never commands more than full stick."""
    n = math.hypot(v[0], v[1])
    return (v[0] / n, v[1] / n) if n > 1.0 else v


def heading_to_ned(v: Vec2, yaw_rad: float) -> Vec2:
    """Sticks::rotateIntoHeadingFrameXY: (forward, right) -> (north, east)."""
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    return c * v[0] - s * v[1], s * v[0] + c * v[1]


class StickYaw:
    """The yaw stick as a filtered yaw rate; the heading setpoint is NaN while turning, then locks."""

    def __init__(self, max_rate_rad_s: float, tau_s: float) -> None:
        self.max_rate_rad_s, self.tau_s = max_rate_rad_s, tau_s
        self.yawspeed = 0.0
        self.yaw_sp = NAN

    def reset(self) -> None:
        self.yawspeed, self.yaw_sp = 0.0, NAN

    def update(self, stick: float, yaw_rad: float, dt_s: float) -> tuple[float, float]:
        """(yaw setpoint, yaw-rate setpoint) for this cycle."""
        target = stick * self.max_rate_rad_s
        self.yawspeed += dt_s / (self.tau_s + dt_s) * (target - self.yawspeed) if dt_s > 0.0 else 0.0
        if abs(self.yawspeed) > FLT_EPSILON:
            self.yaw_sp = NAN  # turning freely
        elif not isfinite(self.yaw_sp):
            self.yaw_sp = yaw_rad  # the turn has died away: lock the heading here
        return self.yaw_sp, self.yawspeed


@dataclass(frozen=True, slots=True)
class StickXYSettings:
    vel_manual: float  # MPC_VEL_MANUAL
    vel_side: float  # MPC_VEL_MAN_SIDE (< 0: as forward)
    vel_back: float  # MPC_VEL_MAN_BACK (< 0: as forward)
    acc_hor: float  # MPC_ACC_HOR
    jerk_max: float  # MPC_JERK_MAX


def stick_tilt_acceleration(sticks: Vec2, yaw_rad: float, tilt_max_rad: float) -> Vec2:
    """StickTiltXY: raw sticks (no deadzone or expo), full stick = MPC_MAN_TILT_MAX (as an acceleration)."""
    max_acc = constrain(math.tan(constrain(tilt_max_rad, 0.0, math.radians(89.0))), 0.02, 3.0) * GRAVITY
    s = heading_to_ned(unit_limited(sticks), yaw_rad)
    return s[0] * max_acc, s[1] * max_acc


class StickAccelerationXY:
    """Position mode's horizontal setpoints: acceleration from the sticks, drag, velocity, position lock."""

    def __init__(self, s: StickXYSettings, vel: Vec2, acc: Vec2) -> None:
        self.s = s
        self.pos_sp: Vec2 = (NAN, NAN)
        self.vel_sp: Vec2 = vel
        self.acc_sp: Vec2 = acc
        self._acc_prev: Vec2 = acc
        self._brake_boost = 1.0

    def update(self, sticks: Vec2, yaw_rad: float, yaw_sp: float, pos: Vec2, vel_feedback: Vec2, dt_s: float,
               tilt_limit_rad: float) -> None:
        """One cycle (generateSetpoints); `sticks` (forward, right) after stick_expo."""
        s = self.s
        acc_scale = 2.0 * s.acc_hor  # "the drag halves the mean": full stick accelerates at 2 MPC_ACC_HOR
        stick = self._scaled(unit_limited(sticks))
        heading = yaw_sp if isfinite(yaw_sp) else yaw_rad
        sn, se = heading_to_ned(stick, heading)
        acc = (sn * acc_scale, se * acc_scale)
        drag = self._drag(acc_scale / s.vel_manual, sn * sn + se * se < FLT_EPSILON, dt_s)
        vel = self.vel_sp
        if self._stopping(acc) and vel[0] * vel[0] + vel[1] * vel[1] < (drag[0] ** 2 + drag[1] ** 2) * dt_s * dt_s:
            drag, vel = (0.0, 0.0), (0.0, 0.0)  # the drag would reverse the velocity: stop instead
        acc = self._jerk_limited((acc[0] - drag[0], acc[1] - drag[1]), dt_s)
        acc = _tilt_limited(acc, tilt_limit_rad)
        vel = (vel[0] + acc[0] * dt_s, vel[1] + acc[1] * dt_s)
        self._lock(vel, pos, vel_feedback)
        self.acc_sp = self._acc_prev = acc

    def _scaled(self, stick: Vec2) -> Vec2:
        """MPC_VEL_MAN_SIDE / _BACK: a smaller top speed sideways or backwards."""
        s, (fwd, right) = self.s, stick
        if s.vel_side >= 0.0:
            right *= s.vel_side / s.vel_manual
        if s.vel_back >= 0.0 and fwd < 0.0:
            fwd *= s.vel_back / s.vel_manual
        return fwd, right

    def _drag(self, coefficient: float, centred: bool, dt_s: float) -> Vec2:
        """A drag on the velocity setpoint, boosted (and more linear at low speed) with the sticks centred."""
        target = max(2.0, math.sqrt(self.s.vel_manual)) if centred else 1.0
        self._brake_boost += dt_s / (0.8 + dt_s) * (target - self._brake_boost)
        c = coefficient * self._brake_boost
        vx, vy = self.vel_sp
        speed = math.hypot(vx, vy)
        boosted = math.sqrt(speed) if speed < 1.0 else speed  # sqrt_linear
        vbx, vby = (vx / speed * boosted, vy / speed * boosted) if speed > 0.0 else (0.0, 0.0)
        k = constrain(self._brake_boost - 1.0, 0.0, 1.0)  # interpolate(boost, 1, 2, 0, 1)
        return c * (k * vbx + (1.0 - k) * vx), c * (k * vby + (1.0 - k) * vy)

    def _stopping(self, acc: Vec2) -> bool:
        """No stick, or the stick just reversed on an axis."""
        prev = self._acc_prev
        return (acc[0] * acc[0] + acc[1] * acc[1] < FLT_EPSILON or _sign(prev[0]) != _sign(acc[0])
                or _sign(prev[1]) != _sign(acc[1]))

    def _jerk_limited(self, acc: Vec2, dt_s: float) -> Vec2:
        """Each axis slews at MPC_JERK_MAX times its share of the change's direction."""
        prev = self._acc_prev
        dx, dy = acc[0] - prev[0], acc[1] - prev[1]
        n = math.hypot(dx, dy)
        if n <= 1e-5:
            return acc
        step_x, step_y = abs(dx / n) * self.s.jerk_max * dt_s, abs(dy / n) * self.s.jerk_max * dt_s
        return prev[0] + constrain(dx, -step_x, step_x), prev[1] + constrain(dy, -step_y, step_y)

    def _lock(self, vel: Vec2, pos: Vec2, vel_feedback: Vec2) -> None:
        """Hold the position once the velocity setpoint is zero; let go (from the controller's velocity) when it
        moves again."""
        moving = vel[0] * vel[0] + vel[1] * vel[1] > FLT_EPSILON
        locked = isfinite(self.pos_sp[0])
        if not moving and not locked:
            self.pos_sp = pos
        elif moving and locked:
            self.pos_sp = (NAN, NAN)
            if isfinite(vel_feedback[0]) and isfinite(vel_feedback[1]):
                vel = vel_feedback
        self.vel_sp = vel


def _tilt_limited(acc: Vec2, tilt_limit_rad: float) -> Vec2:
    limit = math.tan(tilt_limit_rad) * GRAVITY
    n = math.hypot(acc[0], acc[1])
    return (acc[0] / n * limit, acc[1] / n * limit) if n > limit else acc


def _sign(x: float) -> int:
    return (x > 0.0) - (x < 0.0)
