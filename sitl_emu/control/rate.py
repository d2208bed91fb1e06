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

from sitl_emu.params import ParamRegistry
from sitl_emu.types import Vec3

DGYRO_CUTOFF_HZ: Final = 30.0  # IMU_DGYRO_CUTOFF default
_I_FACTOR_RATE: Final = math.radians(400.0)
# the (2 pi fc) of the derivative low-pass; `* dt` comes after, as before
_DGYRO_W: Final = 2.0 * math.pi * DGYRO_CUTOFF_HZ
_NO_SAT: Final = (False, False, False)
# isfinite(x) is written `x - x == 0.0` (exact for floats: finite gives 0.0, inf and NaN give NaN): no call when
# compiled by `make speedups` (mypyc has no isfinite primitive).


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
    def settings(self) -> RateControlSettings:
        return self._settings

    @settings.setter
    def settings(self, s: RateControlSettings) -> None:
        self._settings = s
        self._yaw_tau_s = 1.0 / (2.0 * math.pi * s.yaw_tq_cutoff_hz) if s.yaw_tq_cutoff_hz > 0.0 else 0.0

    @property
    def integrator(self) -> Vec3:
        return self._int[0], self._int[1], self._int[2]

    def update(self, rates: Vec3, rates_sp: Vec3, dt_s: float, landed: bool,
               sat_pos: tuple[bool, bool, bool] = _NO_SAT, sat_neg: tuple[bool, bool, bool] = _NO_SAT) -> Vec3:
        """Normalised torque (roll, pitch, yaw) for the mixer.

        Runs every physics tick, so the gyro derivative and the integrator are inlined here on scalars (same
        operation order as the plain formulas in the docstrings of this module; min/max written as the exactly
        equivalent conditional expressions).
        """
        s = self._settings
        w0, w1, w2 = rates
        prev, self._prev_rates = self._prev_rates, rates
        acc = self._accel
        if prev is not None and dt_s > 0.0:  # gyro derivative through the IMU_DGYRO_CUTOFF low-pass
            b = _DGYRO_W * dt_s
            a = b / (1.0 + b)
            a0, a1, a2 = acc
            acc = self._accel = [a0 + a * ((w0 - prev[0]) / dt_s - a0), a1 + a * ((w1 - prev[1]) / dt_s - a1),
                                 a2 + a * ((w2 - prev[2]) / dt_s - a2)]
        a0, a1, a2 = acc
        p, i, d, ff = s.gain_p, self._int, s.gain_d, s.gain_ff
        sp0, sp1, sp2 = rates_sp
        e0, e1, e2 = sp0 - w0, sp1 - w1, sp2 - w2
        tr = p[0] * e0 + i[0] - d[0] * a0 + ff[0] * sp0
        tp = p[1] * e1 + i[1] - d[1] * a1 + ff[1] * sp1
        ty = p[2] * e2 + i[2] - d[2] * a2 + ff[2] * sp2
        if not landed:
            self._integrate(e0, e1, e2, dt_s, sat_pos, sat_neg)
        if s.yaw_tq_cutoff_hz > 0.0 and dt_s > 0.0:  # AlphaFilter: alpha = dt / (dt + 1 / (2 pi fc))
            alpha = dt_s / (dt_s + self._yaw_tau_s)
            self._yaw_torque += alpha * (ty - self._yaw_torque)
            ty = self._yaw_torque
        return tr, tp, ty

    def _integrate(self, e0: float, e1: float, e2: float, dt_s: float, sat_pos: tuple[bool, bool, bool],
                   sat_neg: tuple[bool, bool, bool]) -> None:
        """The integrator of the three axes (see the module docstring), unrolled: it runs every tick in flight.

        min(e, 0) is `0 if e > 0 else e`, max(e, 0) is `0 if e < 0 else e`, max(0, x) is `x if x > 0 else 0`,
        min(lim, v) is `v if v < lim else lim` and max(-lim, v) is `v if v > -lim else -lim`, exactly."""
        s = self._settings
        g0, g1, g2 = s.gain_i
        l0, l1, l2 = s.int_lim
        p0, p1, p2 = sat_pos
        n0, n1, n2 = sat_neg
        integ = self._int
        if p0:
            e0 = 0.0 if e0 > 0.0 else e0
        if n0:
            e0 = 0.0 if e0 < 0.0 else e0
        f = e0 / _I_FACTOR_RATE
        k = 1.0 - f * f
        v = integ[0] + (k if k > 0.0 else 0.0) * g0 * e0 * dt_s
        if v - v == 0.0:
            v = v if v < l0 else l0
            integ[0] = v if v > -l0 else -l0
        if p1:
            e1 = 0.0 if e1 > 0.0 else e1
        if n1:
            e1 = 0.0 if e1 < 0.0 else e1
        f = e1 / _I_FACTOR_RATE
        k = 1.0 - f * f
        v = integ[1] + (k if k > 0.0 else 0.0) * g1 * e1 * dt_s
        if v - v == 0.0:
            v = v if v < l1 else l1
            integ[1] = v if v > -l1 else -l1
        if p2:
            e2 = 0.0 if e2 > 0.0 else e2
        if n2:
            e2 = 0.0 if e2 < 0.0 else e2
        f = e2 / _I_FACTOR_RATE
        k = 1.0 - f * f
        v = integ[2] + (k if k > 0.0 else 0.0) * g2 * e2 * dt_s
        if v - v == 0.0:
            v = v if v < l2 else l2
            integ[2] = v if v > -l2 else -l2
