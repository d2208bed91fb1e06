"""Offboard setpoint messages -> the vehicle's typed inputs, with PX4's type_mask and frame semantics. Pure functions.

Sources: src/modules/mavlink/mavlink_receiver.cpp handle_message_set_position_target_local_ned (~l.1177),
handle_message_set_position_target_global_int (~l.1294), handle_message_set_attitude_target (~l.1793);
reference 4.4, 4.7, 4.8. A set type_mask bit means "ignore": that component becomes NaN; a cleared bit means the value
is used, even 0. Values that are not finite are treated as not controlled (NaN), never passed to the controllers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from sitl_emu.geo import GeoRef, global_to_ned
from sitl_emu.mavlink.telemetry.messages import rotate_body_to_ned
from sitl_emu.px4 import MavFrame
from sitl_emu.types import AttitudeSetpoint, OffboardControlMode, TrajectorySetpoint, Vec3, VehicleSnapshot

if TYPE_CHECKING:
    from typing import TypeAlias

    from pymavlink.dialects.v20 import development as dialect

    SetpointMessage: TypeAlias = (dialect.MAVLink_set_position_target_local_ned_message
                                  | dialect.MAVLink_set_position_target_global_int_message
                                  | dialect.MAVLink_set_attitude_target_message)

NAN = math.nan
# POSITION_TARGET_TYPEMASK
X_IGNORE, Y_IGNORE, Z_IGNORE = 1, 2, 4
VX_IGNORE, VY_IGNORE, VZ_IGNORE = 8, 16, 32
AX_IGNORE, AY_IGNORE, AZ_IGNORE = 64, 128, 256
FORCE_SET, YAW_IGNORE, YAW_RATE_IGNORE = 512, 1024, 2048
POS_MASK, VEL_MASK, ACC_MASK = 7, 56, 448
# ATTITUDE_TARGET_TYPEMASK
ROLL_RATE_IGNORE, PITCH_RATE_IGNORE, YAW_RATE_IGNORE_ATT = 1, 2, 4
THRUST_BODY_SET, THROTTLE_IGNORE, ATTITUDE_IGNORE = 32, 64, 128

@dataclass(frozen=True, slots=True)
class Decoded:
    """A setpoint to hand the vehicle, or an error text PX4 would print (mode None), or neither (silently dropped)."""

    mode: OffboardControlMode | None = None
    trajectory: TrajectorySetpoint | None = None
    attitude: AttitudeSetpoint | None = None
    error: str | None = None


DROPPED = Decoded()


def decode_local_ned(msg: dialect.MAVLink_set_position_target_local_ned_message, snap: VehicleSnapshot) -> Decoded:
    """SET_POSITION_TARGET_LOCAL_NED: frames LOCAL_NED (1) and BODY_NED (8) only."""
    frame = int(msg.coordinate_frame)
    mask = int(msg.type_mask)
    pos = (msg.x, msg.y, msg.z)
    vel = (msg.vx, msg.vy, msg.vz)
    acc = (msg.afx, msg.afy, msg.afz)
    if frame == MavFrame.LOCAL_NED:
        pos_ned, vel_ned, acc_ned = _masked(pos, mask, 0), _masked(vel, mask, 3), _masked(acc, mask, 6)
    elif frame == MavFrame.BODY_NED:
        pos_ned = (NAN, NAN, NAN)
        vel_ned = _yaw_rotated(vel, snap.euler_rad[2]) if not mask & VEL_MASK else (NAN, NAN, NAN)
        acc_ned = _finite(rotate_body_to_ned(snap.q_wxyz, acc)) if not mask & ACC_MASK else (NAN, NAN, NAN)
    else:
        return Decoded(error=f"SET_POSITION_TARGET_LOCAL_NED coordinate frame {frame} unsupported")
    return _trajectory("SET_POSITION_TARGET_LOCAL_NED", mask, pos_ned, vel_ned, acc_ned,
                       msg.yaw, msg.yaw_rate)


def decode_global_int(msg: dialect.MAVLink_set_position_target_global_int_message, snap: VehicleSnapshot
                      ) -> Decoded:
    """SET_POSITION_TARGET_GLOBAL_INT: lat/lon projected into the local frame; z per frame as PX4 codes it."""
    frame = int(msg.coordinate_frame)
    mask = int(msg.type_mask)
    if frame not in (MavFrame.GLOBAL_INT, MavFrame.GLOBAL_RELATIVE_ALT_INT, MavFrame.GLOBAL_TERRAIN_ALT_INT):
        return Decoded(error=f"SET_POSITION_TARGET_GLOBAL_INT invalid coordinate frame {frame}")
    if not snap.position_valid:  # no global reference: silently dropped
        return DROPPED
    pos_ned: Vec3 = (NAN, NAN, NAN)
    if not mask & POS_MASK:
        z = _global_z(frame, float(msg.alt), snap)
        if z is None:
            return DROPPED
        ref = GeoRef(snap.ref_lat_deg, snap.ref_lon_deg, snap.ref_alt_amsl_m)  # PX4's MapProjection::project
        x, y, _ = global_to_ned(ref, msg.lat_int * 1e-7, msg.lon_int * 1e-7, snap.ref_alt_amsl_m)
        pos_ned = _finite((x, y, z))
    vel = _masked((msg.vx, msg.vy, msg.vz), mask, 3)
    acc = _masked((msg.afx, msg.afy, msg.afz), mask, 6)
    return _trajectory("SET_POSITION_TARGET_GLOBAL_INT", mask, pos_ned, vel, acc, msg.yaw,
                       msg.yaw_rate)


def decode_attitude_target(msg: dialect.MAVLink_set_attitude_target_message) -> Decoded:
    """SET_ATTITUDE_TARGET: attitude and/or body rates, with thrust; otherwise dropped."""
    mask = int(msg.type_mask)
    use_attitude = not mask & ATTITUDE_IGNORE
    use_rates = not mask & ROLL_RATE_IGNORE and not mask & PITCH_RATE_IGNORE
    has_thrust = not mask & THROTTLE_IGNORE or bool(mask & THRUST_BODY_SET)
    if not (use_attitude or use_rates) or not has_thrust:
        return DROPPED
    w, x, y, z = (float(v) for v in msg.q)
    q = (w, x, y, z)
    if use_attitude and (not all(math.isfinite(v) for v in q) or sum(v * v for v in q) < 1e-6):
        return DROPPED
    thrust = _thrust_body(msg, mask)
    if thrust is None:
        return DROPPED
    yaw_rate = NAN if mask & YAW_RATE_IGNORE_ATT else msg.body_yaw_rate
    rates = _finite((msg.body_roll_rate, msg.body_pitch_rate, yaw_rate)) if use_rates else (NAN, NAN, NAN)
    setpoint = AttitudeSetpoint(q_wxyz=_normalized(q) if use_attitude else None,
                                body_rates_rad_s=rates, thrust_body=thrust)
    mode = OffboardControlMode(attitude=bool(use_attitude), body_rate=bool(use_rates))
    return Decoded(mode=mode, attitude=setpoint)


def _trajectory(name: str, mask: int, pos: Vec3, vel: Vec3, acc: Vec3, yaw: float, yaw_rate: float) -> Decoded:
    has_pos, has_vel, has_acc = _any_finite(pos), _any_finite(vel), _any_finite(acc)
    if has_acc and mask & FORCE_SET:
        return Decoded(error=f"{name} force not supported")
    if not (has_pos or has_vel or has_acc):
        return Decoded(error=f"{name} invalid")
    yaw_sp = NAN if mask & YAW_IGNORE or not math.isfinite(yaw) else float(yaw)
    yawspeed_sp = NAN if mask & YAW_RATE_IGNORE or not math.isfinite(yaw_rate) else float(yaw_rate)
    mode = OffboardControlMode(position=has_pos, velocity=has_vel, acceleration=has_acc,
                               attitude=math.isfinite(yaw_sp), body_rate=math.isfinite(yawspeed_sp))
    return Decoded(mode=mode, trajectory=TrajectorySetpoint(pos, vel, acc, yaw_sp, yawspeed_sp))


def _global_z(frame: int, alt_m: float, snap: VehicleSnapshot) -> float | None:
    if not math.isfinite(alt_m):
        return None
    if frame == MavFrame.GLOBAL_INT:
        return snap.ref_alt_amsl_m - alt_m
    if frame == MavFrame.GLOBAL_RELATIVE_ALT_INT:
        if snap.home is None:
            return None
        return (snap.home.alt_amsl_m - alt_m) - snap.ref_alt_amsl_m  # as PX4 codes it (reference 4.7)
    return None  # GLOBAL_TERRAIN_ALT_INT needs terrain data, which SIH does not estimate


def _thrust_body(msg: dialect.MAVLink_set_attitude_target_message, mask: int) -> Vec3 | None:
    if mask & THRUST_BODY_SET:
        tx, ty, tz = (float(v) for v in getattr(msg, "thrust_body", (0.0, 0.0, 0.0)))
        return (tx, ty, tz) if all(math.isfinite(v) for v in (tx, ty, tz)) else None
    thrust = float(msg.thrust)
    if not math.isfinite(thrust):
        return None
    return (0.0, 0.0, -min(max(thrust, 0.0), 1.0))


def _masked(values: tuple[float, float, float], mask: int, first_bit: int) -> Vec3:
    out = [NAN if mask & (1 << (first_bit + i)) else float(v) for i, v in enumerate(values)]
    return _finite((out[0], out[1], out[2]))


def _yaw_rotated(v_body: tuple[float, float, float], yaw_rad: float) -> Vec3:
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    vx, vy, vz = (float(v) for v in v_body)
    return _finite((c * vx - s * vy, s * vx + c * vy, vz))


def _finite(v: tuple[float, float, float]) -> Vec3:
    return (_f(v[0]), _f(v[1]), _f(v[2]))


def _f(x: float) -> float:
    return float(x) if math.isfinite(x) else NAN


def _any_finite(v: Vec3) -> bool:
    return any(math.isfinite(x) for x in v)


def _normalized(q: tuple[float, float, float, float]) -> tuple[float, float, float, float]:
    n = math.sqrt(sum(x * x for x in q))
    return (q[0] / n, q[1] / n, q[2] / n, q[3] / n)
