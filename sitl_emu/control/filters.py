"""The derivative filter the controllers share: controllib's BlockDerivative (src/lib/controllib/BlockDerivative.cpp).

A finite difference through a first-order low-pass. The position controller differentiates the velocity with it
(MPC_VELD_LP), the rate controller the gyro (IMU_DGYRO_CUTOFF, as sensors/vehicle_angular_velocity does).
"""

from __future__ import annotations

import math

from sitl_emu.types import Vec3


class LowPassDerivative:
    def __init__(self, cutoff_hz: float) -> None:
        self.cutoff_hz = cutoff_hz
        # the previous sample, valid once _has_prev: a plain Vec3 stays unboxed in the compiled build, where an
        # optional one would be built as a Python tuple of three floats every update
        self._prev: Vec3 = (0.0, 0.0, 0.0)
        self._has_prev = False
        self._out: Vec3 = (0.0, 0.0, 0.0)

    @property
    def cutoff_hz(self) -> float:
        return self._cutoff_hz

    @cutoff_hz.setter
    def cutoff_hz(self, hz: float) -> None:
        self._cutoff_hz = hz
        self._omega = 2.0 * math.pi * hz  # rad/s

    def reset(self) -> None:
        self._has_prev = False
        self._out = (0.0, 0.0, 0.0)

    def update(self, x: Vec3, dt_s: float) -> Vec3:
        """The filtered derivative of x; unchanged on the first sample (no previous value) or without a time step."""
        prev, had_prev = self._prev, self._has_prev
        self._prev, self._has_prev = x, True
        if not had_prev or dt_s <= 0.0:
            return self._out
        b = self._omega * dt_s
        alpha = b / (1.0 + b) if self._cutoff_hz > 0.0 else 1.0
        out = self._out
        self._out = (out[0] + alpha * ((x[0] - prev[0]) / dt_s - out[0]),
                     out[1] + alpha * ((x[1] - prev[1]) / dt_s - out[1]),
                     out[2] + alpha * ((x[2] - prev[2]) / dt_s - out[2]))
        return self._out
