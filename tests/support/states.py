"""Vehicle states for tests: a quadrotor hovering, an attitude from Euler angles."""

from __future__ import annotations

import math

from sitl_emu.control.qmath import q_from_yaw
from sitl_emu.physics import RigidBodyState, SihConfig
from sitl_emu.types import Vec4


def q_from_euler(roll_rad: float, pitch_rad: float, yaw_rad: float) -> Vec4:
    """The attitude of ZYX Euler angles (the inverse of qmath.euler_from_q)."""
    cr, sr = math.cos(roll_rad / 2.0), math.sin(roll_rad / 2.0)
    cp, sp = math.cos(pitch_rad / 2.0), math.sin(pitch_rad / 2.0)
    cy, sy = math.cos(yaw_rad / 2.0), math.sin(yaw_rad / 2.0)
    return (cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy)


def hover_state(altitude_m: float, cfg: SihConfig | None = None, yaw_rad: float = 0.0) -> RigidBodyState:
    """A vehicle hovering at `altitude_m` above the ground, motors at the hover command ."""
    cfg = cfg or SihConfig()
    h = cfg.hover_command
    return RigidBodyState(pos_ned_m=(0.0, 0.0, -altitude_m), q_wxyz=q_from_yaw(yaw_rad), motors=(h, h, h, h),
                          on_ground=False)
