"""Hover thrust estimate, in the spirit of PX4's mc_hover_thrust_estimator (MPC_USE_HTE).

PX4 runs a one-state Kalman filter on the vertical acceleration; here a first-order filter on the same measurement
(hover = T_up g / (g + a_up)) gives the estimate the position controller and the land detector need. It only learns
while flying and slow vertically (|vz| < 2 m/s, HTE_VZ_THR), and starts from MPC_THR_HOVER.
"""

from __future__ import annotations

G = 9.80665
VZ_THRESHOLD_M_S = 2.0  # HTE_VZ_THR
TIME_CONSTANT_S = 2.0


class HoverThrustEstimator:
    def __init__(self, initial: float = 0.5, lo: float = 0.1, hi: float = 0.9) -> None:
        self.lo, self.hi = lo, hi
        self.reset(initial)

    def reset(self, initial: float) -> None:
        self.estimate = min(self.hi, max(self.lo, initial))

    def update(self, thrust_up: float, acc_up_m_s2: float, vz_m_s: float, dt_s: float) -> float:
        """Feed the vertical thrust setpoint (0..1, positive up) and the measured upward acceleration."""
        if abs(vz_m_s) < VZ_THRESHOLD_M_S and thrust_up > 0.0 and G + acc_up_m_s2 > 1.0:
            meas = thrust_up * G / (G + acc_up_m_s2)
            k = min(1.0, dt_s / TIME_CONSTANT_S)
            self.estimate = min(self.hi, max(self.lo, self.estimate + k * (meas - self.estimate)))
        return self.estimate
