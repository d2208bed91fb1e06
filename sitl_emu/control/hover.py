"""Hover thrust estimate after PX4's mc_hover_thrust_estimator (MPC_USE_HTE).

A one-state EKF (zero_order_hover_thrust_ekf.cpp): the state is the hover thrust, the measurement the upward
acceleration a = g T / h - g for the upward thrust setpoint T. Innovation gate, measurement-noise learning and the
large-offset recovery follow PX4; so does the gating of MulticopterHoverThrustEstimator.cpp: it runs only armed,
in the air (not landed and more than 1 m above the ground), it trusts measurements less at speed (HTE_VZ_THR,
HTE_VXY_THR), and the estimate is "valid" once its variance stayed below 0.001 for 2 s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final

from sitl_emu.control.qmath import constrain, hypot, isfinite

G: Final = 9.80665
NOISE_LEARNING_TAU_S: Final = 2.0
LPF_TAU_S: Final = 1.0
VALID_VAR: Final = 0.001
VALID_HYSTERESIS_US: Final = 2_000_000


@dataclass(frozen=True, slots=True)
class HoverThrustSettings:
    initial: float = 0.5  # MPC_THR_HOVER
    process_noise: float = 0.0036  # HTE_HT_NOISE
    gate: float = 3.0  # HTE_ACC_GATE
    err_init: float = 0.1  # HTE_HT_ERR_INIT
    vz_thr: float = 2.0  # HTE_VZ_THR
    vxy_thr: float = 10.0  # HTE_VXY_THR
    thr_range: float = 0.2  # HTE_THR_RANGE


class HoverThrustEstimator:
    def __init__(self, settings: HoverThrustSettings | None = None) -> None:
        self.settings = settings or HoverThrustSettings()
        self.reset()

    @property
    def settings(self) -> HoverThrustSettings:
        return self._settings

    @settings.setter
    def settings(self, s: HoverThrustSettings) -> None:
        self._settings = s
        self._bounds = (min(max(s.initial - s.thr_range, 0.0), 0.8), min(max(s.initial + s.thr_range, 0.2), 0.9))
        self._gate_sq = s.gate ** 2

    def reset(self) -> None:
        s = self._settings
        self.estimate = min(0.9, max(0.1, s.initial))
        self.var = s.err_init * s.err_init
        self.valid = False
        self._acc_var = 5.0
        self._residual_lpf = 0.0
        self._ratio_lpf = 0.0
        self._valid_since_us: int | None = None

    @property
    def bounds(self) -> tuple[float, float]:
        """The estimate's range: MPC_THR_HOVER +- HTE_THR_RANGE within 0..0.8 / 0.2..0.9."""
        return self._bounds

    def update(self, thrust_up: float, acc_up_m_s2: float, vel_ned_m_s: tuple[float, float, float], dt_s: float,
               now_us: int) -> bool:
        """One in-air cycle; returns whether the estimate is valid (then the controller should use it)."""
        if not (0.001 < dt_s < 1.0) or not isfinite(thrust_up):
            return self.valid
        s = self._settings
        self.var += s.process_noise * s.process_noise * dt_s * dt_s  # predict (as PX4: var += q dt^2)
        # trust the measurement less at speed: noise x (1 + the larger excess over HTE_VZ_THR / HTE_VXY_THR)^2
        vz_coeff = abs(vel_ned_m_s[2]) - s.vz_thr + 1.0
        vxy_coeff = hypot(vel_ned_m_s[0], vel_ned_m_s[1]) - s.vxy_thr + 1.0
        coeff = vxy_coeff if vxy_coeff > vz_coeff else vz_coeff
        scale = math.pow(coeff if coeff > 1.0 else 1.0, 2.0)  # x ** 2 is the same pow(), compiled a boxed call
        self._fuse(acc_up_m_s2, thrust_up, scale, dt_s)
        ok = self.var < VALID_VAR
        if ok and self._valid_since_us is None:
            self._valid_since_us = now_us
        elif not ok:
            self._valid_since_us = None
        self.valid = self._valid_since_us is not None and now_us - self._valid_since_us >= VALID_HYSTERESIS_US
        return self.valid

    def _fuse(self, acc_z: float, thrust: float, scale: float, dt_s: float) -> None:
        """ZeroOrderHoverThrustEkf::fuseAccZ with the innovation gate, noise learning and large-offset recovery."""
        h = self.estimate
        jac = -G * thrust / (h * h)
        r = self._acc_var * scale
        innov_var = jac * self.var * jac + r
        innov_var = r if r > innov_var else innov_var
        innov = acc_z - (G * thrust / h - G)
        ratio = innov * innov / (self._gate_sq * innov_var)
        residual = innov
        if ratio < 1.0:
            k = self.var * jac / innov_var
            lo, hi = self._bounds
            self.estimate = constrain(h + k * innov, lo, hi)
            self.var = constrain((1.0 - k * jac) * self.var, 1e-10, 1.0)
            residual = acc_z - (G * thrust / self.estimate - G)
        elif abs(self._ratio_lpf) > 0.2:  # large offset: bump the variance to recover
            self.var += 1e3 * self._settings.process_noise ** 2 * dt_s
        alpha = dt_s / (LPF_TAU_S + dt_s)
        self._residual_lpf += alpha * (residual - self._residual_lpf)
        self._ratio_lpf += alpha * (math.copysign(ratio if ratio < 1.0 else 1.0, innov) - self._ratio_lpf)
        alpha_n = dt_s / (NOISE_LEARNING_TAU_S + dt_s)
        res = residual - self._residual_lpf
        acc_var = (1.0 - alpha_n) * self._acc_var + alpha_n * (res * res + jac * self.var * jac)
        self._acc_var = constrain(acc_var, 1.0, 400.0)
