"""What the view draws, as plain numbers: the vehicle's arms from its attitude, the fence box.

Pure geometry, no Rerun: the world of the view is east-north-up (x east, y north, z up, metres) so the ground is
the x-y plane; the vehicle reports north-east-down (NED) positions and its attitude as the rotation from its body
frame (forward-right-down, FRD) to NED, as PX4's vehicle_attitude (and MAVLink's ATTITUDE_QUATERNION) give it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]  # w, x, y, z

ARM_M = 0.25  # a 500 mm-class quad (SIH's default airframe is about that size), drawn bigger than life below
DRAW_SCALE = 4.0  # so the vehicle stays visible from a view of the whole fence


@dataclass(frozen=True, slots=True)
class Frame:
    """One vehicle at one instant, whatever side saw it (the emulator's snapshot or a client's MAVLink)."""

    time_s: float
    pos_ned_m: Vec3 | None
    q_wxyz: Quat | None = None
    setpoint_ned_m: Vec3 | None = None
    home_ned_m: Vec3 | None = None
    mode: str = "-"
    armed: bool = False
    sticks: tuple[float, float, float, float] | None = None  # forward, right, up (throttle), yaw, each -1..1


@dataclass(frozen=True, slots=True)
class FenceBox:
    """A box around home: `half_width_m` north and east, from `min_alt_m` to `max_alt_m` above home."""

    home_ned_m: Vec3
    half_width_m: float
    min_alt_m: float
    max_alt_m: float


def ned_to_enu(v: Vec3) -> Vec3:
    return (v[1], v[0], -v[2])


def rotate(q: Quat, v: Vec3) -> Vec3:
    """v rotated by the unit quaternion q (body to world)."""
    w, x, y, z = q
    vx, vy, vz = v
    # t = 2 q_vec x v; v' = v + w t + q_vec x t
    tx, ty, tz = 2 * (y * vz - z * vy), 2 * (z * vx - x * vz), 2 * (x * vy - y * vx)
    return (vx + w * tx + y * tz - z * ty, vy + w * ty + z * tx - x * tz, vz + w * tz + x * ty - y * tx)


def body_arms(pos_ned_m: Vec3, q_wxyz: Quat | None) -> list[list[Vec3]]:
    """The four arms of an X quad (each a segment from the centre) and a short mast up, in the view's world.

    The first arm is the front right one (PX4's motor 1 of the quad X), the second the rear left; the front pair
    is drawn first so a colour per strip can mark the nose.
    """
    q = q_wxyz or (1.0, 0.0, 0.0, 0.0)
    arm = ARM_M * DRAW_SCALE
    d = arm / math.sqrt(2.0)
    tips_frd = [(d, d, 0.0), (d, -d, 0.0), (-d, -d, 0.0), (-d, d, 0.0), (0.0, 0.0, -arm / 2)]
    centre = ned_to_enu(pos_ned_m)
    strips = []
    for tip in tips_frd:
        r = ned_to_enu(rotate(q, tip))
        strips.append([centre, (centre[0] + r[0], centre[1] + r[1], centre[2] + r[2])])
    return strips


def fence_box(fence: FenceBox) -> tuple[Vec3, Vec3]:
    """(centre, half_size) of the fence in the view's world."""
    hx, hy, hz = ned_to_enu(fence.home_ned_m)
    mid_alt = (fence.min_alt_m + fence.max_alt_m) / 2
    half_height = (fence.max_alt_m - fence.min_alt_m) / 2
    return (hx, hy, hz + mid_alt), (fence.half_width_m, fence.half_width_m, half_height)


def euler_to_q(roll: float, pitch: float, yaw: float) -> Quat:
    """PX4's ZYX Euler angles (as MAVLink's ATTITUDE sends them) to a quaternion, body to NED."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy)
