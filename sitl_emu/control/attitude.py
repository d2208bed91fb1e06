"""Multicopter attitude controller after PX4's AttitudeControl (src/modules/mc_att_control/AttitudeControl/).

Quaternion P control with roll/pitch prioritised over yaw (MC_YAW_WEIGHT), yaw-rate feed-forward about the world z
axis, and per-axis rate limits (MC_*RATE_MAX).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from math import acos, asin, cos, isfinite, sin, sqrt
from typing import Final

from sitl_emu.control.qmath import constrain, q_from_two_vectors
from sitl_emu.params import ParamRegistry
from sitl_emu.types import Vec3, Vec4

_NEAR_ONE: Final = 1.0 - 1e-5  # Quaternion(src, dst) degenerate when the reduced attitude is a half turn


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
        self._lim = s.rate_max_rad_s

    def update(self, q: Vec4, q_sp: Vec4, yawspeed_ff_rad_s: float = 0.0) -> Vec3:
        """Body rate setpoint (rad/s, FRD) driving attitude q towards q_sp.

        Runs every physics tick, so it is written flat on scalars: the quaternion helpers of qmath (dcm_z,
        q_from_two_vectors, q_mul, q_inv, q_canonical) are inlined with their exact operation order, including the
        products with the zero components, so every float (and every signed zero) is the one the helpers give.
        """
        qw, qx, qy, qz = q
        sw, sx, sy, sz = q_sp
        # reduced attitude: only tilt the thrust axis, neglecting yaw: rotation taking dcm_z(q) onto dcm_z(q_sp)
        a0, a1, a2 = 2.0 * (qx * qz + qw * qy), 2.0 * (qy * qz - qw * qx), 1.0 - 2.0 * (qx * qx + qy * qy)
        b0, b1, b2 = 2.0 * (sx * sz + sw * sy), 2.0 * (sy * sz - sw * sx), 1.0 - 2.0 * (sx * sx + sy * sy)
        cx, cy, cz = a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0
        d = a0 * b0 + a1 * b1 + a2 * b2
        if sqrt(cx * cx + cy * cy + cz * cz) < 1e-5 and d < 0.0:  # 180 degrees: the general helper
            rw, rx, ry, rz = q_from_two_vectors((a0, a1, a2), (b0, b1, b2))
        else:  # q_normalized((d + |a| |b|, c))
            rw = d + sqrt((a0 * a0 + a1 * a1 + a2 * a2) * (b0 * b0 + b1 * b1 + b2 * b2))
            n = sqrt(rw * rw + cx * cx + cy * cy + cz * cz)
            if n > 0.0:
                rw, rx, ry, rz = rw / n, cx / n, cy / n, cz / n
            else:
                rw, rx, ry, rz = 1.0, 0.0, 0.0, 0.0
        if abs(rx) > _NEAR_ONE or abs(ry) > _NEAR_ONE:
            rw, rx, ry, rz = sw, sx, sy, sz
        else:  # q_mul(q_red, q)
            rw, rx, ry, rz = (rw * qw - rx * qx - ry * qy - rz * qz, rw * qx + rx * qw + ry * qz - rz * qy,
                              rw * qy - rx * qz + ry * qw + rz * qx, rw * qz + rx * qy - ry * qx + rz * qw)
        # mix in the yaw part with weight yaw_w: q_mix = canonical(q_inv(qd_red) * q_sp), only w and z are needed
        nx, ny, nz = -rx, -ry, -rz
        mw = rw * sw - nx * sx - ny * sy - nz * sz
        mz = rw * sz + nx * sy - ny * sx + nz * sw
        if not mw >= 0.0:
            mw, mz = -mw, -mz
        mw = -1.0 if mw < -1.0 else (1.0 if mw > 1.0 else mw)
        mz = -1.0 if mz < -1.0 else (1.0 if mz > 1.0 else mz)
        yaw_w = self._yaw_w
        c, s = cos(yaw_w * acos(mw)), sin(yaw_w * asin(mz))
        # qd = qd_red * (c, 0, 0, s)
        dw = rw * c - rx * 0.0 - ry * 0.0 - rz * s
        dx = rw * 0.0 + rx * c + ry * s - rz * 0.0
        dy = rw * 0.0 - rx * s + ry * c + rz * 0.0
        dz = rw * s + rx * 0.0 - ry * 0.0 + rz * c
        # qe = canonical(q_inv(q) * qd)
        nx, ny, nz = -qx, -qy, -qz
        ew = qw * dw - nx * dx - ny * dy - nz * dz
        ex = qw * dx + nx * dw + ny * dz - nz * dy
        ey = qw * dy - nx * dz + ny * dw + nz * dx
        ez = qw * dz + nx * dy - ny * dx + nz * dw
        if not ew >= 0.0:
            ex, ey, ez = -ex, -ey, -ez
        kp0, kp1, kp2 = self._kp
        r0, r1, r2 = 2.0 * ex * kp0, 2.0 * ey * kp1, 2.0 * ez * kp2
        if yawspeed_ff_rad_s != 0.0 and isfinite(yawspeed_ff_rad_s):
            # world z axis in the body frame: third row of R
            r0 += 2.0 * (qx * qz - qw * qy) * yawspeed_ff_rad_s
            r1 += 2.0 * (qy * qz + qw * qx) * yawspeed_ff_rad_s
            r2 += (1.0 - 2.0 * (qx * qx + qy * qy)) * yawspeed_ff_rad_s
        l0, l1, l2 = self._lim
        return (-l0 if r0 < -l0 else (l0 if r0 > l0 else r0), -l1 if r1 < -l1 else (l1 if r1 > l1 else r1),
                -l2 if r2 < -l2 else (l2 if r2 > l2 else r2))
