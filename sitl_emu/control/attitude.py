"""Multicopter attitude controller after PX4's AttitudeControl (src/modules/mc_att_control/AttitudeControl/).

Quaternion P control with roll/pitch prioritised over yaw (MC_YAW_WEIGHT), yaw-rate feed-forward about the world z
axis, and per-axis rate limits (MC_*RATE_MAX).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from sitl_emu.control.qmath import constrain, dcm_z, q_canonical, q_from_two_vectors, q_inv, q_mul
from sitl_emu.params import ParamRegistry
from sitl_emu.types import Vec3, Vec4


@dataclass(frozen=True, slots=True)
class AttitudeControlSettings:
    gain_p: Vec3 = (4.0, 4.0, 2.8)
    yaw_weight: float = 0.4
    rate_max_rad_s: Vec3 = (math.radians(220.0), math.radians(220.0), math.radians(200.0))

    @classmethod
    def from_params(cls, reg: ParamRegistry) -> AttitudeControlSettings:
        g = reg.get
        return cls(
            gain_p=(g("MC_ROLL_P"), g("MC_PITCH_P"), g("MC_YAW_P")), yaw_weight=g("MC_YAW_WEIGHT"),
            rate_max_rad_s=(math.radians(g("MC_ROLLRATE_MAX")), math.radians(g("MC_PITCHRATE_MAX")),
                            math.radians(g("MC_YAWRATE_MAX"))),
        )


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

    def update(self, q: Vec4, q_sp: Vec4, yawspeed_ff_rad_s: float = 0.0) -> Vec3:
        """Body rate setpoint (rad/s, FRD) driving attitude q towards q_sp."""
        yaw_w, kp = self._yaw_w, self._kp
        # reduced attitude: only tilt the thrust axis, neglecting yaw
        qd_red = q_from_two_vectors(dcm_z(q), dcm_z(q_sp))
        if abs(qd_red[1]) > 1.0 - 1e-5 or abs(qd_red[2]) > 1.0 - 1e-5:
            qd_red = q_sp
        else:
            qd_red = q_mul(qd_red, q)
        # mix in the yaw part with weight yaw_w
        q_mix = q_canonical(q_mul(q_inv(qd_red), q_sp))
        w = constrain(q_mix[0], -1.0, 1.0)
        z = constrain(q_mix[3], -1.0, 1.0)
        qd = q_mul(qd_red, (math.cos(yaw_w * math.acos(w)), 0.0, 0.0, math.sin(yaw_w * math.asin(z))))
        qe = q_canonical(q_mul(q_inv(q), qd))
        r0, r1, r2 = 2.0 * qe[1] * kp[0], 2.0 * qe[2] * kp[1], 2.0 * qe[3] * kp[2]
        if yawspeed_ff_rad_s != 0.0 and math.isfinite(yawspeed_ff_rad_s):
            # world z axis in the body frame: third row of R
            qw, qx, qy, qz = q
            r0 += 2.0 * (qx * qz - qw * qy) * yawspeed_ff_rad_s
            r1 += 2.0 * (qy * qz + qw * qx) * yawspeed_ff_rad_s
            r2 += (1.0 - 2.0 * (qx * qx + qy * qy)) * yawspeed_ff_rad_s
        lim = self._settings.rate_max_rad_s
        return constrain(r0, -lim[0], lim[0]), constrain(r1, -lim[1], lim[1]), constrain(r2, -lim[2], lim[2])
