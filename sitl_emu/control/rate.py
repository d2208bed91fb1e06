"""Multicopter rate controller after PX4's RateControl (src/lib/rate_control/rate_control.cpp).

torque = P e + I + FF sp - D d(omega)/dt, with MC_*RATE_K scaling P, I and D (mc_rate_control). The integrator
is frozen while landed, does not grow in the direction of an allocation saturation, shrinks its gain for large errors
(i_factor, 400 deg/s) and is clamped to MC_*_INT_LIM. The angular acceleration is the gyro derivative through a
30 Hz low-pass (IMU_DGYRO_CUTOFF). The yaw torque goes through a low-pass MC_YAW_TQ_CUTOFF
(MulticopterRateControl.cpp _output_lpf_yaw).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final

from sitl_emu.control.filters import LowPassDerivative
from sitl_emu.control.qmath import constrain, isfinite, sub
from sitl_emu.types import Vec3

DGYRO_CUTOFF_HZ: Final = 30.0  # IMU_DGYRO_CUTOFF default
I_FACTOR_RATE_RAD_S: Final = math.radians(400.0)
Flags3 = tuple[bool, bool, bool]
_NO_SAT: Final = (False, False, False)


@dataclass(frozen=True, slots=True)
class RateControlSettings:
    gain_p: Vec3 = (0.15, 0.15, 0.2)
    gain_i: Vec3 = (0.2, 0.2, 0.1)
    gain_d: Vec3 = (0.003, 0.003, 0.0)
    gain_ff: Vec3 = (0.0, 0.0, 0.0)
    int_lim: Vec3 = (0.3, 0.3, 0.3)
    yaw_tq_cutoff_hz: float = 2.0


class RateControl:
    def __init__(self, settings: RateControlSettings | None = None) -> None:
        self.settings = settings or RateControlSettings()
        self._angular_accel = LowPassDerivative(DGYRO_CUTOFF_HZ)
        self.reset()

    def reset(self) -> None:
        self._int: Vec3 = (0.0, 0.0, 0.0)
        self._angular_accel.reset()
        self._yaw_torque = 0.0

    @property
    def settings(self) -> RateControlSettings:
        return self._settings

    @settings.setter
    def settings(self, s: RateControlSettings) -> None:
        self._settings = s
        self._yaw_tau_s = 1.0 / (2.0 * math.pi * s.yaw_tq_cutoff_hz) if s.yaw_tq_cutoff_hz > 0.0 else 0.0

    @property
    def integrator(self) -> Vec3:
        return self._int

    def update(self, rates: Vec3, rates_sp: Vec3, dt_s: float, landed: bool, sat_pos: Flags3 = _NO_SAT,
               sat_neg: Flags3 = _NO_SAT) -> Vec3:
        """Normalised torque (roll, pitch, yaw) for the mixer (RateControl::update).

        sat_pos / sat_neg: the mixer could not give more (less) torque on that axis last time."""
        s = self._settings
        angular_accel = self._angular_accel.update(rates, dt_s)
        e, i, acc, sp = sub(rates_sp, rates), self._int, angular_accel, rates_sp
        p, d, ff = s.gain_p, s.gain_d, s.gain_ff
        # PID with feed-forward: P e + I - D d(omega)/dt + FF sp
        torque = (p[0] * e[0] + i[0] - d[0] * acc[0] + ff[0] * sp[0],
                  p[1] * e[1] + i[1] - d[1] * acc[1] + ff[1] * sp[1],
                  p[2] * e[2] + i[2] - d[2] * acc[2] + ff[2] * sp[2])
        if not landed:
            ki, lim = s.gain_i, s.int_lim
            self._int = (_integrate(i[0], e[0], ki[0], lim[0], dt_s, sat_pos[0], sat_neg[0]),
                         _integrate(i[1], e[1], ki[1], lim[1], dt_s, sat_pos[1], sat_neg[1]),
                         _integrate(i[2], e[2], ki[2], lim[2], dt_s, sat_pos[2], sat_neg[2]))
        if s.yaw_tq_cutoff_hz > 0.0 and dt_s > 0.0:  # AlphaFilter: alpha = dt / (dt + 1 / (2 pi fc))
            self._yaw_torque += dt_s / (dt_s + self._yaw_tau_s) * (torque[2] - self._yaw_torque)
            return torque[0], torque[1], self._yaw_torque
        return torque


def _integrate(integral: float, error: float, gain_i: float, limit: float, dt_s: float, sat_pos: bool,
               sat_neg: bool) -> float:
    """RateControl::updateIntegral for one axis: the new integrator value."""
    if (sat_pos and error > 0.0) or (sat_neg and error < 0.0):
        error = 0.0  # no further growth into the allocation's saturation
    i_factor = error / I_FACTOR_RATE_RAD_S
    i_factor = 1.0 - i_factor * i_factor  # less gain for large errors, none beyond 400 deg/s
    value = integral + (i_factor if i_factor > 0.0 else 0.0) * gain_i * error * dt_s
    return constrain(value, -limit, limit) if isfinite(value) else integral
