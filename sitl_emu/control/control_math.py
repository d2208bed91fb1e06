"""The position controller's vector maths, after PX4's ControlMath (src/modules/mc_pos_control/PositionControl/
ControlMath.cpp): NaN-aware sums, the horizontal velocity limit, the tilt limit and thrust vector -> attitude.
"""

from __future__ import annotations

from math import cos, sin, sqrt
from typing import Final

from sitl_emu.control.qmath import acos, constrain, cross, hypot, isfinite, normalized, q_from_dcm_columns
from sitl_emu.types import Vec3, Vec4

FLT_EPSILON: Final = 1.2e-7


def add_if_not_nan3(setpoint: Vec3, addition: Vec3) -> Vec3:
    """ControlMath::addIfNotNanVector3f: setpoint + addition per component, where a NaN term does not count (NaN if
    both are NaN)."""
    s0, s1, s2 = setpoint
    a0, a1, a2 = addition
    return ((s0 + a0 if isfinite(a0) else s0) if isfinite(s0) else a0,
            (s1 + a1 if isfinite(a1) else s1) if isfinite(s1) else a1,
            (s2 + a2 if isfinite(a2) else s2) if isfinite(s2) else a2)


def constrain_xy(v0: tuple[float, float], v1: tuple[float, float], vmax: float) -> tuple[float, float]:
    """ControlMath::constrainXY: limit |v0 + v1| to vmax, keeping as much of v0 as possible."""
    v0x, v0y = v0
    v1x, v1y = v1
    sx, sy = v0x + v1x, v0y + v1y
    if hypot(sx, sy) <= vmax:
        return sx, sy
    n0 = hypot(v0x, v0y)
    if n0 >= vmax:
        return (v0x / n0 * vmax, v0y / n0 * vmax) if n0 > 0.0 else (0.0, 0.0)
    if hypot(v1x - v0x, v1y - v0y) < 0.001:
        return v0x / n0 * vmax, v0y / n0 * vmax
    n1 = hypot(v1x, v1y)
    if n0 < 0.001:
        return v1x / n1 * vmax, v1y / n1 * vmax
    # the point on the line v0 + s u (u = v1 / |v1|) at distance vmax from the origin
    ux, uy = v1x / n1, v1y / n1
    m = ux * v0x + uy * v0y
    c = v0x * v0x + v0y * v0y - vmax * vmax
    s = -m + sqrt(m * m - c)
    return v0x + ux * s, v0y + uy * s


def limit_tilt(body_z: Vec3, max_angle_rad: float) -> Vec3:
    """ControlMath::limitTilt: body_z (a unit vector) tilted at most max_angle_rad from the world z axis (0, 0, 1)."""
    angle = acos(constrain(body_z[2], -1.0, 1.0))
    angle = max_angle_rad if max_angle_rad < angle else angle
    rx, ry = body_z[0], body_z[1]  # the direction of the tilt, in the horizontal plane
    rn = hypot(rx, ry)
    if rn * rn < FLT_EPSILON:
        rx, ry, rn = 1.0, 0.0, 1.0
    s = sin(angle)
    return s * rx / rn, s * ry / rn, cos(angle)


def bodyz_to_attitude(body_z: Vec3, yaw_rad: float) -> Vec4:
    """ControlMath::bodyzToAttitude: the attitude whose body z axis is body_z (world frame), with the given heading."""
    if body_z[0] * body_z[0] + body_z[1] * body_z[1] + body_z[2] * body_z[2] < FLT_EPSILON:
        body_z = (0.0, 0.0, 1.0)  # no thrust: level
    body_z = normalized(body_z)
    y_c = (-sin(yaw_rad), cos(yaw_rad), 0.0)  # the heading's y axis in the horizontal plane
    body_x = cross(y_c, body_z)
    if body_z[2] < 0.0:  # upside down: keep the nose on the heading
        body_x = (-body_x[0], -body_x[1], -body_x[2])
    if abs(body_z[2]) < 1e-6:  # thrust horizontal: the nose points down
        body_x = (0.0, 0.0, 1.0)
    body_x = normalized(body_x)
    body_y = cross(body_z, body_x)
    return q_from_dcm_columns(body_x, body_y, body_z)
