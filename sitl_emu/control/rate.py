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

from sitl_emu.params import ParamRegistry
from sitl_emu.types import Vec3

DGYRO_CUTOFF_HZ = 30.0  # IMU_DGYRO_CUTOFF default
_I_FACTOR_RATE = math.radians(400.0)


@dataclass(frozen=True, slots=True)
class RateControlSettings:
    gain_p: Vec3 = (0.15, 0.15, 0.2)
    gain_i: Vec3 = (0.2, 0.2, 0.1)
    gain_d: Vec3 = (0.003, 0.003, 0.0)
    gain_ff: Vec3 = (0.0, 0.0, 0.0)
    int_lim: Vec3 = (0.3, 0.3, 0.3)
    yaw_tq_cutoff_hz: float = 2.0

    @classmethod
    def from_params(cls, reg: ParamRegistry) -> RateControlSettings:
        g = reg.get
        axes = ("ROLL", "PITCH", "YAW")
        k = [g(f"MC_{a}RATE_K") for a in axes]
        return cls(
            gain_p=tuple(k[i] * g(f"MC_{a}RATE_P") for i, a in enumerate(axes)),  # type: ignore[arg-type]
            gain_i=tuple(k[i] * g(f"MC_{a}RATE_I") for i, a in enumerate(axes)),  # type: ignore[arg-type]
            gain_d=tuple(k[i] * g(f"MC_{a}RATE_D") for i, a in enumerate(axes)),  # type: ignore[arg-type]
            gain_ff=tuple(g(f"MC_{a}RATE_FF") for a in axes),  # type: ignore[arg-type]
            int_lim=(g("MC_RR_INT_LIM"), g("MC_PR_INT_LIM"), g("MC_YR_INT_LIM")),
            yaw_tq_cutoff_hz=g("MC_YAW_TQ_CUTOFF"),
        )


class RateControl:
    def __init__(self, settings: RateControlSettings | None = None) -> None:
        self.settings = settings or RateControlSettings()
        self._int = [0.0, 0.0, 0.0]
        self._prev_rates: Vec3 | None = None
        self._accel: list[float] = [0.0, 0.0, 0.0]
        self._yaw_torque = 0.0

    def reset(self) -> None:
        self._int = [0.0, 0.0, 0.0]
        self._prev_rates = None
        self._accel = [0.0, 0.0, 0.0]
        self._yaw_torque = 0.0

    @property
    def integrator(self) -> Vec3:
        return self._int[0], self._int[1], self._int[2]

    def update(self, rates: Vec3, rates_sp: Vec3, dt_s: float, landed: bool,
               sat_pos: tuple[bool, bool, bool] = (False, False, False),
               sat_neg: tuple[bool, bool, bool] = (False, False, False)) -> Vec3:
        """Normalised torque (roll, pitch, yaw) for the mixer."""
        s = self.settings
        a0, a1, a2 = self._angular_accel(rates, dt_s)
        p, i, d, ff = s.gain_p, self._int, s.gain_d, s.gain_ff
        e0, e1, e2 = rates_sp[0] - rates[0], rates_sp[1] - rates[1], rates_sp[2] - rates[2]
        tr = p[0] * e0 + i[0] - d[0] * a0 + ff[0] * rates_sp[0]
        tp = p[1] * e1 + i[1] - d[1] * a1 + ff[1] * rates_sp[1]
        ty = p[2] * e2 + i[2] - d[2] * a2 + ff[2] * rates_sp[2]
        if not landed:
            self._update_integral([e0, e1, e2], dt_s, sat_pos, sat_neg)
        if s.yaw_tq_cutoff_hz > 0.0 and dt_s > 0.0:  # AlphaFilter: alpha = dt / (dt + 1 / (2 pi fc))
            alpha = dt_s / (dt_s + 1.0 / (2.0 * math.pi * s.yaw_tq_cutoff_hz))
            self._yaw_torque += alpha * (ty - self._yaw_torque)
            ty = self._yaw_torque
        return tr, tp, ty

    def _angular_accel(self, rates: Vec3, dt_s: float) -> list[float]:
        prev, self._prev_rates = self._prev_rates, rates
        if prev is None or dt_s <= 0.0:
            return self._accel
        b = 2.0 * math.pi * DGYRO_CUTOFF_HZ * dt_s
        a = b / (1.0 + b)
        self._accel = [self._accel[i] + a * ((rates[i] - prev[i]) / dt_s - self._accel[i]) for i in range(3)]
        return self._accel

    def _update_integral(self, err: list[float], dt_s: float, sat_pos: tuple[bool, bool, bool],
                         sat_neg: tuple[bool, bool, bool]) -> None:
        s = self.settings
        for i in range(3):
            e = err[i]
            if sat_pos[i]:
                e = min(e, 0.0)
            if sat_neg[i]:
                e = max(e, 0.0)
            f = e / _I_FACTOR_RATE
            i_factor = max(0.0, 1.0 - f * f)
            v = self._int[i] + i_factor * s.gain_i[i] * e * dt_s
            if math.isfinite(v):
                self._int[i] = max(-s.int_lim[i], min(s.int_lim[i], v))
