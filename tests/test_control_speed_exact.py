"""The flat, inlined hot paths of the control cascade compute exactly the floats of the readable formulas.

The per-tick controllers (attitude, rate, mixer, position control's attitude construction) are written on scalars
for speed. Each test here runs the plain composition of the qmath helpers / min / max that the code was written
from and requires bit-identical results (repr, so a -0.0 versus 0.0 also fails) on random and edge-case inputs:
a flight replayed from a log must not change by one bit because the code got faster.
"""

from __future__ import annotations

import math
import random

import pytest

from sitl_emu.control.attitude import AttitudeControl
from sitl_emu.control.mixer import mix
from sitl_emu.control.position import bodyz_to_attitude
from sitl_emu.control.qmath import (
    constrain,
    cross,
    dcm_z,
    normalized,
    q_canonical,
    q_from_dcm_columns,
    q_from_euler,
    q_from_two_vectors,
    q_inv,
    q_mul,
    q_normalized,
)
from sitl_emu.control.rate import RateControl, RateControlSettings
from sitl_emu.types import Vec3, Vec4

RNG_SEED = 4


def _reference_attitude(att: AttitudeControl, q: Vec4, q_sp: Vec4, yawspeed_ff: float) -> Vec3:
    """AttitudeControl::update as a composition of the qmath helpers (the readable form)."""
    yaw_w, kp = att._yaw_w, att._kp
    qd_red = q_from_two_vectors(dcm_z(q), dcm_z(q_sp))
    if abs(qd_red[1]) > 1.0 - 1e-5 or abs(qd_red[2]) > 1.0 - 1e-5:
        qd_red = q_sp
    else:
        qd_red = q_mul(qd_red, q)
    q_mix = q_canonical(q_mul(q_inv(qd_red), q_sp))
    w = constrain(q_mix[0], -1.0, 1.0)
    z = constrain(q_mix[3], -1.0, 1.0)
    qd = q_mul(qd_red, (math.cos(yaw_w * math.acos(w)), 0.0, 0.0, math.sin(yaw_w * math.asin(z))))
    qe = q_canonical(q_mul(q_inv(q), qd))
    r0, r1, r2 = 2.0 * qe[1] * kp[0], 2.0 * qe[2] * kp[1], 2.0 * qe[3] * kp[2]
    if yawspeed_ff != 0.0 and math.isfinite(yawspeed_ff):
        qw, qx, qy, qz = q
        r0 += 2.0 * (qx * qz - qw * qy) * yawspeed_ff
        r1 += 2.0 * (qy * qz + qw * qx) * yawspeed_ff
        r2 += (1.0 - 2.0 * (qx * qx + qy * qy)) * yawspeed_ff
    lim = att.settings.rate_max_rad_s
    return constrain(r0, -lim[0], lim[0]), constrain(r1, -lim[1], lim[1]), constrain(r2, -lim[2], lim[2])


def _random_q(rng: random.Random) -> Vec4:
    return q_from_euler(rng.uniform(-1.2, 1.2), rng.uniform(-1.2, 1.2), rng.uniform(-math.pi, math.pi))


def _attitude_cases() -> list[tuple[Vec4, Vec4, float]]:
    rng = random.Random(RNG_SEED)
    level, yawed = (1.0, 0.0, 0.0, 0.0), q_from_euler(0.0, 0.0, 2.0)
    cases = [(level, level, 0.0), (level, yawed, 0.0), (yawed, level, 0.3), (level, (0.0, 0.0, 0.0, 1.0), 0.0),
             (level, (0.0, 1.0, 0.0, 0.0), 0.0), ((0.0, 1.0, 0.0, 0.0), level, -0.5), (level, level, math.nan),
             ((-1.0, 0.0, 0.0, 0.0), level, 0.0), (level, q_from_euler(math.pi, 0.0, 0.0), 0.0)]
    for _ in range(3000):
        ff = rng.choice((0.0, rng.uniform(-2.0, 2.0)))
        q = _random_q(rng)
        q_sp = rng.choice((_random_q(rng), q, (q[0], q[1], q[2], -q[3])))
        cases.append((q, q_sp, ff))
    return cases


def test_attitude_control_flat_path_matches_the_quaternion_formula_bit_for_bit():
    att = AttitudeControl()
    for q, q_sp, ff in _attitude_cases():
        assert repr(att.update(q, q_sp, ff)) == repr(_reference_attitude(att, q, q_sp, ff)), (q, q_sp, ff)


def _reference_bodyz(bz: Vec3, yaw_rad: float) -> Vec4:
    """ControlMath::bodyzToAttitude as a composition of the qmath helpers."""
    if bz[0] * bz[0] + bz[1] * bz[1] + bz[2] * bz[2] < 1.2e-7:
        bz = (0.0, 0.0, 1.0)
    bz = normalized(bz)
    bx = cross((-math.sin(yaw_rad), math.cos(yaw_rad), 0.0), bz)
    if bz[2] < 0.0:
        bx = (-bx[0], -bx[1], -bx[2])
    if abs(bz[2]) < 1e-6:
        bx = (0.0, 0.0, 1.0)
    bx = normalized(bx)
    return q_from_dcm_columns(bx, cross(bz, bx), bz)


def test_thrust_vector_to_attitude_flat_path_matches_the_dcm_formula_bit_for_bit():
    rng = random.Random(RNG_SEED)
    cases = [((0.0, 0.0, 0.0), 0.0), ((0.0, 0.0, 1.0), 0.0), ((0.0, 0.0, 0.6), math.pi), ((0.3, 0.0, 0.0), 1.0),
             ((0.0, 0.0, -1.0), 0.5), ((-0.0, 0.0, 0.5), -0.0)]
    cases += [((rng.uniform(-0.7, 0.7), rng.uniform(-0.7, 0.7), rng.uniform(-1.0, 1.0)),
               rng.uniform(-4.0, 4.0)) for _ in range(3000)]
    for bz, yaw in cases:
        assert repr(bodyz_to_attitude(bz, yaw)) == repr(_reference_bodyz(bz, yaw)), (bz, yaw)
        assert repr(q_normalized(bodyz_to_attitude(bz, yaw))) == repr(q_normalized(_reference_bodyz(bz, yaw)))


class _ReferenceRate:
    """RateControl with the per-axis loops, list comprehensions and min/max of its readable form."""

    def __init__(self, s: RateControlSettings) -> None:
        self.s, self.integ, self.acc, self.yaw = s, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], 0.0
        self.prev: Vec3 | None = None

    def update(self, rates: Vec3, sp: Vec3, dt: float, landed: bool, sat_pos: tuple[bool, bool, bool],
               sat_neg: tuple[bool, bool, bool]) -> Vec3:
        s = self.s
        if self.prev is not None and dt > 0.0:
            b = 2.0 * math.pi * 30.0 * dt
            a = b / (1.0 + b)
            self.acc = [self.acc[i] + a * ((rates[i] - self.prev[i]) / dt - self.acc[i]) for i in range(3)]
        self.prev = rates
        err = [sp[i] - rates[i] for i in range(3)]
        out = [s.gain_p[i] * err[i] + self.integ[i] - s.gain_d[i] * self.acc[i] + s.gain_ff[i] * sp[i]
               for i in range(3)]
        if not landed:
            for i in range(3):
                e = err[i]
                if sat_pos[i]:
                    e = min(e, 0.0)
                if sat_neg[i]:
                    e = max(e, 0.0)
                f = e / math.radians(400.0)
                v = self.integ[i] + max(0.0, 1.0 - f * f) * s.gain_i[i] * e * dt
                if math.isfinite(v):
                    self.integ[i] = max(-s.int_lim[i], min(s.int_lim[i], v))
        alpha = dt / (dt + 1.0 / (2.0 * math.pi * s.yaw_tq_cutoff_hz))
        self.yaw += alpha * (out[2] - self.yaw)
        return out[0], out[1], self.yaw


def test_rate_control_flat_path_matches_the_per_axis_formula_bit_for_bit():
    rng = random.Random(RNG_SEED)
    settings = RateControlSettings(gain_ff=(0.01, 0.02, 0.03), int_lim=(0.05, 0.3, 0.1))
    fast, ref = RateControl(settings), _ReferenceRate(settings)
    for k in range(5000):
        rates = tuple(rng.choice((0.0, -0.0, rng.gauss(0.0, 2.0), rng.gauss(0.0, 20.0))) for _ in range(3))
        sp = tuple(rng.choice((0.0, rng.gauss(0.0, 3.0), rng.gauss(0.0, 15.0))) for _ in range(3))
        sat_pos = tuple(rng.random() < 0.2 for _ in range(3))
        sat_neg = tuple(rng.random() < 0.2 for _ in range(3))
        landed = k % 97 < 5
        got = fast.update(rates, sp, 0.004, landed, sat_pos, sat_neg)  # type: ignore[arg-type]
        want = ref.update(rates, sp, 0.004, landed, sat_pos, sat_neg)  # type: ignore[arg-type]
        assert repr(got) == repr(want), k
        assert repr(fast.integrator) == repr(tuple(ref.integ)), k


@pytest.mark.parametrize("torque,thrust", [((0.0, 0.0, 0.0), 0.5), ((0.1, -0.05, 0.02), 0.45), ((-0.0, 0.0, -0.0), 0.0),
                                           ((0.0, 0.0, 0.0), 1.0), ((0.3, 0.3, 0.3), 0.95), ((math.nan, 0.1, 0.0), 0.5),
                                           ((0.1, math.inf, 0.0), 0.5), ((0.0, 0.0, 0.0), math.nan)])
def test_mixer_takes_the_plain_mix_exactly_when_no_motor_saturates(torque, thrust):
    motors, sat_pos, sat_neg = mix(torque, thrust)
    roll, pitch, yaw = (t if math.isfinite(t) else 0.0 for t in torque)
    thr = thrust if math.isfinite(thrust) else 0.0
    k = 1.0 / math.sqrt(2.0)  # the mixer's 0.707 roll/pitch scale
    r, p = k * roll, k * pitch
    plain = (thr - r + p + yaw, thr + r - p + yaw, thr + r + p - yaw, thr - r - p - yaw)
    if min(plain) >= 0.0 and max(plain) <= 1.0:
        assert repr(motors) == repr(plain) and sat_pos == sat_neg == (False, False, False)
    else:
        assert all(0.0 <= m <= 1.0 for m in motors)
