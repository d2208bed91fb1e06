"""STABILIZED (and MANUAL) on a multicopter: the sticks are the attitude and the throttle is the thrust.

After mc_att_control's generate_attitude_setpoint (src/modules/mc_att_control/mc_att_control_main.cpp) and its
throttle_curve: no flight task and no position control. Per tick:
- the right stick tilts the vehicle, full stick = MPC_MAN_TILT_MAX (raw sticks, no deadzone or expo);
- the yaw stick commands a yaw rate (flight_tasks/sticks.py StickYaw), the heading locking once it stops; with the
  throttle fully down the heading lock is dropped (so the arming gesture does not wind up a yaw error);
- the throttle goes through PX4's curve (MPC_THR_CURVE 0): low stick = the minimum thrust (0 on the ground,
  MPC_MANTHR_MIN in the air, slewed at 0.05/s), centre = the hover thrust, full = MPC_THR_MAX; after arming the
  thrust is held at 0 for COM_SPOOLUP_TIME, then its cap rises at 0.5/s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final

from sitl_emu.commander.manual_control import CENTRED
from sitl_emu.control.qmath import constrain, isfinite, q_from_yaw, q_mul
from sitl_emu.flight_tasks.sticks import NAN, StickYaw, stick_expo
from sitl_emu.navigator.setpoint import NavInput
from sitl_emu.params import ParamRegistry
from sitl_emu.types import AttitudeSetpoint, ManualControlSetpoint, Vec4

MIN_THRUST_SLEW_PER_S: Final = 0.05
MAX_THRUST_SLEW_PER_S: Final = 0.5
YAW_RESET_THROTTLE: Final = -0.9


@dataclass(frozen=True, slots=True)
class StabilizedSettings:
    deadzone: float  # MAN_DEADZONE
    yaw_rate_rad_s: float  # MPC_MAN_Y_MAX
    yaw_tau_s: float  # MPC_MAN_Y_TAU
    tilt_max_rad: float  # MPC_MAN_TILT_MAX
    manthr_min: float  # MPC_MANTHR_MIN
    thr_hover: float  # MPC_THR_HOVER
    thr_max: float  # MPC_THR_MAX
    spoolup_us: int  # COM_SPOOLUP_TIME

    @classmethod
    def from_params(cls, p: ParamRegistry) -> StabilizedSettings:
        return cls(float(p["MAN_DEADZONE"]), math.radians(float(p["MPC_MAN_Y_MAX"])), float(p["MPC_MAN_Y_TAU"]),
                   math.radians(float(p["MPC_MAN_TILT_MAX"])), float(p["MPC_MANTHR_MIN"]), float(p["MPC_THR_HOVER"]),
                   float(p["MPC_THR_MAX"]), int(float(p["COM_SPOOLUP_TIME"]) * 1e6))


class StabilizedMode:
    """The attitude and thrust setpoint from the sticks, for one stay in the mode."""

    def __init__(self, nav: NavInput, params: ParamRegistry) -> None:
        self._params, self._version = params, params.version
        self.s = StabilizedSettings.from_params(params)
        self.sticks: ManualControlSetpoint = CENTRED
        self._yaw = StickYaw(self.s.yaw_rate_rad_s, self.s.yaw_tau_s)
        self._min_thrust = 0.0 if nav.landed else self.s.manthr_min
        # entered on the ground (just armed): the spool-up hold; entered in the air: no cap
        self._spoolup_until_us = nav.time_us + self.s.spoolup_us if nav.landed else nav.time_us
        self._max_thrust = 0.0 if nav.landed else 1.0

    def update(self, nav: NavInput, dt_s: float) -> AttitudeSetpoint:
        if self._params.version != self._version:
            self._version, self.s = self._params.version, StabilizedSettings.from_params(self._params)
        sticks, s = self.sticks, self.s
        if sticks.throttle < YAW_RESET_THROTTLE:
            self._yaw.yaw_sp = NAN
        yaw_sp, yawspeed = self._yaw.update(stick_expo(sticks.yaw, s.deadzone), nav.yaw_rad, dt_s)
        q_sp = q_mul(q_from_yaw(yaw_sp if isfinite(yaw_sp) else nav.yaw_rad), self._tilt(sticks))
        thrust = self._thrust(nav, sticks.throttle, dt_s)
        return AttitudeSetpoint(q_sp, (NAN, NAN, yawspeed), (0.0, 0.0, -thrust))

    def _tilt(self, sticks: ManualControlSetpoint) -> Vec4:
        """Roll right and pitch forward (nose down) by the sticks, as one rotation of at most MPC_MAN_TILT_MAX."""
        tilt = self.s.tilt_max_rad
        vx, vy = sticks.roll * tilt, -sticks.pitch * tilt
        angle = math.hypot(vx, vy)
        if angle <= 0.0:
            return 1.0, 0.0, 0.0, 0.0
        if angle > tilt:
            vx, vy, angle = vx / angle * tilt, vy / angle * tilt, tilt
        k = math.sin(0.5 * angle) / angle
        return math.cos(0.5 * angle), vx * k, vy * k, 0.0

    def _thrust(self, nav: NavInput, throttle: float, dt_s: float) -> float:
        """throttle_curve (MPC_THR_CURVE 0) under the spool-up cap."""
        s = self.s
        target_min = 0.0 if nav.landed else s.manthr_min
        step = MIN_THRUST_SLEW_PER_S * dt_s
        self._min_thrust = constrain(target_min, self._min_thrust - step, self._min_thrust + step)
        if nav.time_us >= self._spoolup_until_us:
            self._max_thrust = min(1.0, self._max_thrust + MAX_THRUST_SLEW_PER_S * dt_s)
        t = constrain(throttle, -1.0, 1.0)
        if t < 0.0:
            thrust = self._min_thrust + (t + 1.0) * (s.thr_hover - self._min_thrust)
        else:
            thrust = s.thr_hover + t * (s.thr_max - s.thr_hover)
        return min(thrust, self._max_thrust)
