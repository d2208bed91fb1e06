"""Vehicle states for tests (an attitude from Euler angles is flightview.scene.euler_to_q)."""

from __future__ import annotations

from sitl_emu.control.qmath import q_from_yaw
from sitl_emu.physics import RigidBodyState, SihConfig


def hover_state(altitude_m: float, cfg: SihConfig | None = None, yaw_rad: float = 0.0) -> RigidBodyState:
    """A vehicle hovering at `altitude_m` above the ground, motors at the hover command."""
    cfg = cfg or SihConfig()
    h = cfg.hover_command
    return RigidBodyState(pos_ned_m=(0.0, 0.0, -altitude_m), q_wxyz=q_from_yaw(yaw_rad), motors=(h, h, h, h),
                          on_ground=False)
