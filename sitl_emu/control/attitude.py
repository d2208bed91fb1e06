"""Multicopter attitude controller after PX4's AttitudeControl (src/modules/mc_att_control/AttitudeControl/
AttitudeControl.cpp).

Quaternion P control with roll/pitch prioritised over yaw (MC_YAW_WEIGHT), yaw-rate feed-forward about the world z
axis, and per-axis rate limits (MC_*RATE_MAX).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from math import cos, sin
from typing import Final

from sitl_emu.control.qmath import (
    acos,
    add,
    asin,
    constrain,
    constrain3,
    dcm_z,
    isfinite,
    q_between,
    q_canonical,
    q_from_two_vectors,
    q_inv,
    q_mul,
    scale,
)
from sitl_emu.types import Vec3, Vec4

_NEAR_ONE: Final = 1.0 - 1e-5  # Quaternion(src, dst) degenerate when the reduced attitude is a half turn


@dataclass(frozen=True, slots=True)
class AttitudeControlSettings:
    gain_p: Vec3 = (4.0, 4.0, 2.8)
    yaw_weight: float = 0.4
    rate_max_rad_s: Vec3 = (math.radians(220.0), math.radians(220.0), math.radians(200.0))


class AttitudeControl:
    def __init__(self, settings: AttitudeControlSettings | None = None) -> None:
        self.settings = settings or AttitudeControlSettings()

    @property
    def settings(self) -> AttitudeControlSettings:
        return self._settings

    @settings.setter
    def settings(self, s: AttitudeControlSettings) -> None:
        self._settings = s
        self._yaw_w = constrain(s.yaw_weight, 0.0, 1.0)
        # setProportionalGain: compensate the yaw weight's rescaling of the output
        self._kp = s.gain_p if self._yaw_w <= 1e-4 else (s.gain_p[0], s.gain_p[1], s.gain_p[2] / self._yaw_w)
        self._rate_min = (-s.rate_max_rad_s[0], -s.rate_max_rad_s[1], -s.rate_max_rad_s[2])

    def update(self, q: Vec4, q_sp: Vec4, yawspeed_ff_rad_s: float = 0.0) -> Vec3:
        """Body rate setpoint (rad/s, FRD) driving attitude q towards q_sp (AttitudeControl::update)."""
        # reduced attitude: the shortest rotation that tilts the thrust axis onto the setpoint's, neglecting yaw
        qd_red = q_from_two_vectors(dcm_z(q), dcm_z(q_sp))
        if abs(qd_red[1]) > _NEAR_ONE or abs(qd_red[2]) > _NEAR_ONE:
            qd_red = q_sp  # a half turn: the reduced attitude is undefined, use the full setpoint
        else:
            qd_red = q_mul(qd_red, q)
        # mix the full and the reduced setpoint: the yaw part only with weight yaw_w
        q_mix = q_canonical(q_between(qd_red, q_sp))
        w, z = constrain(q_mix[0], -1.0, 1.0), constrain(q_mix[3], -1.0, 1.0)
        qd = q_mul(qd_red, (cos(self._yaw_w * acos(w)), 0.0, 0.0, sin(self._yaw_w * asin(z))))
        # quaternion attitude control law, qe the rotation from q to qd
        qe = q_canonical(q_between(q, qd))
        rate_sp = (2.0 * qe[1] * self._kp[0], 2.0 * qe[2] * self._kp[1], 2.0 * qe[3] * self._kp[2])
        if yawspeed_ff_rad_s != 0.0 and isfinite(yawspeed_ff_rad_s):
            # feed-forward the yaw rate about the world z axis, expressed in the body frame
            rate_sp = add(rate_sp, scale(dcm_z(q_inv(q)), yawspeed_ff_rad_s))
        return constrain3(rate_sp, self._rate_min, self._settings.rate_max_rad_s)
