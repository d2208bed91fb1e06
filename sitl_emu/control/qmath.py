"""Small quaternion and vector helpers on plain float tuples (w-first quaternions, NED/FRD frames).

Semantics follow PX4's matrix library (src/lib/matrix/matrix/Quaternion.hpp): Hamilton product, q rotates body
vectors into the world frame, `dcm_z` is the body z axis expressed in the world frame.
"""

from __future__ import annotations

import math
from typing import Final

from sitl_emu.types import Vec3, Vec4

# The math functions mypyc has no primitive for (it has sqrt, sin, cos, ...), for the tick path: compiled, a call of
# `math.atan2` looks the name up in the math module first, one of these reads a C static (ARCHITECTURE.md, "On the
# tick path"). The very same functions, so both builds compute the same bits.
atan2: Final = math.atan2
acos: Final = math.acos
asin: Final = math.asin
hypot: Final = math.hypot
RAD_TO_DEG: Final = 180.0 / math.pi  # CPython's math.degrees and math.radians multiply by these very constants
DEG_TO_RAD: Final = math.pi / 180.0


def degrees(rad: float) -> float:
    """math.degrees(rad), the same product, compiled without a boxed call."""
    return rad * RAD_TO_DEG


def radians(deg: float) -> float:
    """math.radians(deg), the same product, compiled without a boxed call."""
    return deg * DEG_TO_RAD


def q_mul(a: Vec4, b: Vec4) -> Vec4:
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw)


def q_inv(q: Vec4) -> Vec4:
    """Inverse of a unit quaternion (its conjugate)."""
    return q[0], -q[1], -q[2], -q[3]


def q_between(a: Vec4, b: Vec4) -> Vec4:
    """The rotation from unit quaternion a to b: q_mul(q_inv(a), b), PX4's `a.inversed() * b`, multiplied out."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (aw * bw + ax * bx + ay * by + az * bz,
            aw * bx - ax * bw - ay * bz + az * by,
            aw * by + ax * bz - ay * bw - az * bx,
            aw * bz - ax * by + ay * bx - az * bw)


def q_normalized(q: Vec4) -> Vec4:
    w, x, y, z = q
    n = math.sqrt(w * w + x * x + y * y + z * z)
    if not n > 0.0:
        return 1.0, 0.0, 0.0, 0.0
    return w / n, x / n, y / n, z / n


def q_canonical(q: Vec4) -> Vec4:
    """The same rotation with a non-negative scalar part (PX4 Quaternion::canonical)."""
    return q if q[0] >= 0.0 else (-q[0], -q[1], -q[2], -q[3])


def dcm_z(q: Vec4) -> Vec3:
    """Third column of the rotation matrix: the body z axis in the world frame."""
    w, x, y, z = q
    return 2.0 * (x * z + w * y), 2.0 * (y * z - w * x), 1.0 - 2.0 * (x * x + y * y)


def q_from_two_vectors(src: Vec3, dst: Vec3) -> Vec4:
    """Shortest rotation taking src onto dst (PX4 Quaternion(src, dst) constructor)."""
    cx, cy, cz = cross(src, dst)
    sx, sy, sz = src
    dx, dy, dz = dst
    d = sx * dx + sy * dy + sz * dz  # src . dst
    if math.sqrt(cx * cx + cy * cy + cz * cz) < 1e-5 and d < 0.0:
        # 180 degrees: rotate about any axis orthogonal to src
        ax, ay, az = abs(src[0]), abs(src[1]), abs(src[2])
        if ax < ay:
            axis = (1.0, 0.0, 0.0) if ax < az else (0.0, 0.0, 1.0)
        else:
            axis = (0.0, 1.0, 0.0) if ay < az else (0.0, 0.0, 1.0)
        cx, cy, cz = cross(src, axis)
        return q_normalized((0.0, cx, cy, cz))
    return q_normalized((d + math.sqrt((sx * sx + sy * sy + sz * sz) * (dx * dx + dy * dy + dz * dz)), cx, cy, cz))


def q_from_dcm_columns(bx: Vec3, by: Vec3, bz: Vec3) -> Vec4:
    """Quaternion of the rotation matrix whose columns are bx, by, bz (Shepperd's method, as PX4's Dcm->Quat)."""
    r00, r11, r22 = bx[0], by[1], bz[2]
    tr = r00 + r11 + r22
    if tr > 0.0:
        s = math.sqrt(tr + 1.0)
        w = 0.5 * s
        s = 0.5 / s
        return q_normalized((w, (by[2] - bz[1]) * s, (bz[0] - bx[2]) * s, (bx[1] - by[0]) * s))
    if r00 >= r11 and r00 >= r22:
        s = math.sqrt(1.0 + r00 - r11 - r22)
        x = 0.5 * s
        s = 0.5 / s
        return q_normalized(((by[2] - bz[1]) * s, x, (by[0] + bx[1]) * s, (bx[2] + bz[0]) * s))
    if r11 >= r22:
        s = math.sqrt(1.0 + r11 - r00 - r22)
        y = 0.5 * s
        s = 0.5 / s
        return q_normalized(((bz[0] - bx[2]) * s, (by[0] + bx[1]) * s, y, (bz[1] + by[2]) * s))
    s = math.sqrt(1.0 + r22 - r00 - r11)
    z = 0.5 * s
    s = 0.5 / s
    return q_normalized(((bx[1] - by[0]) * s, (bx[2] + bz[0]) * s, (bz[1] + by[2]) * s, z))


def q_from_yaw(yaw_rad: float) -> Vec4:
    """A level attitude with the given heading."""
    return math.cos(yaw_rad / 2.0), 0.0, 0.0, math.sin(yaw_rad / 2.0)


def euler_from_q(q: Vec4) -> Vec3:
    """(roll, pitch, yaw) in radians, ZYX convention as PX4's Eulerf."""
    w, x, y, z = q
    roll = atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x))))
    return roll, pitch, yaw_from_q(q)


def yaw_from_q(q: Vec4) -> float:
    """Heading in radians (the yaw of the ZYX Euler angles)."""
    w, x, y, z = q
    return atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def tilt_from_q(q: Vec4) -> float:
    """Angle between the body z axis and the world down axis, in radians."""
    return acos(max(-1.0, min(1.0, dcm_z(q)[2])))


def rotate_world_to_body(q: Vec4, v: Vec3) -> Vec3:
    """R^T v: a world-frame (NED) vector in the body frame (FRD), R being the rotation matrix of q."""
    w, x, y, z = q
    v0, v1, v2 = v
    r00, r01, r02 = 1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y)
    r10, r11, r12 = 2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x)
    r20, r21, r22 = 2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y)
    return r00 * v0 + r10 * v1 + r20 * v2, r01 * v0 + r11 * v1 + r21 * v2, r02 * v0 + r12 * v1 + r22 * v2


def add(a: Vec3, b: Vec3) -> Vec3:
    return a[0] + b[0], a[1] + b[1], a[2] + b[2]


def sub(a: Vec3, b: Vec3) -> Vec3:
    return a[0] - b[0], a[1] - b[1], a[2] - b[2]


def scale(a: Vec3, k: float) -> Vec3:
    return a[0] * k, a[1] * k, a[2] * k


def emult(a: Vec3, b: Vec3) -> Vec3:
    """Element-wise product (PX4 Vector3f::emult)."""
    return a[0] * b[0], a[1] * b[1], a[2] * b[2]


def cross(a: Vec3, b: Vec3) -> Vec3:
    a0, a1, a2 = a
    b0, b1, b2 = b
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


def norm(a: Vec3) -> float:
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


def normalized(a: Vec3) -> Vec3:
    a0, a1, a2 = a
    n = math.sqrt(a0 * a0 + a1 * a1 + a2 * a2)
    return (a0 / n, a1 / n, a2 / n) if n > 0.0 else (0.0, 0.0, 0.0)


def isfinite(x: float) -> bool:
    """math.isfinite for a float, written as arithmetic (see ARCHITECTURE.md, On the tick path): x - x is 0.0 for
    every finite x and NaN for inf and NaN."""
    return x - x == 0.0


def all_finite3(v: Vec3) -> bool:
    """Every component of v finite, in one expression (the vector form of isfinite above): each
    finite component times 0.0 is +-0.0 and so is their sum (no overflow, unlike a plain sum), while an inf or NaN
    component makes its product NaN, and the sum with it."""
    return v[0] * 0.0 + v[1] * 0.0 + v[2] * 0.0 == 0.0


def at_most(v: float, limit: float) -> float:
    """min(v, limit) as PX4's math::min, a NaN `v` passing through (as in constrain below)."""
    return limit if limit < v else v


def at_least(v: float, limit: float) -> float:
    """max(v, limit) as PX4's math::max, a NaN `v` passing through (as in constrain below)."""
    return limit if limit > v else v


def constrain(v: float, lo: float, hi: float) -> float:
    """Like PX4's math::constrain: NaN passes through."""
    return lo if v < lo else (hi if v > hi else v)


def constrain3(v: Vec3, lo: Vec3, hi: Vec3) -> Vec3:
    """Element-wise constrain (PX4 matrix::constrain)."""
    v0, v1, v2 = v
    l0, l1, l2 = lo
    h0, h1, h2 = hi
    return (l0 if v0 < l0 else (h0 if v0 > h0 else v0), l1 if v1 < l1 else (h1 if v1 > h1 else v1),
            l2 if v2 < l2 else (h2 if v2 > h2 else v2))
