"""Stick commands -> local-NED position setpoints, with the fence and altitude limits. Pure functions, no I/O.

Frames: MAVLink LOCAL_NED (x north, y east, z down), as PX4's EKF local frame. Stick forward flies north (x+),
right flies east (y+), up climbs (z-), whatever the vehicle's heading (no body-frame rotation).

Two control styles:
- `step` (the seed offboard node): the setpoint is the vehicle's position plus `step_m` x stick; centred sticks
  keep the last setpoint, so the vehicle holds where it was left.
- `velocity`: the sticks command a velocity that moves the setpoint; the setpoint stays on a short leash ahead of
  the vehicle and carries the commanded velocity as feed-forward, so releasing the sticks holds position. Near the
  fence the commanded speed towards it is limited to what can still brake to a stop at the edge.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from joyfly.types import StickCommand

Vec3 = tuple[float, float, float]

# POSITION_TARGET_TYPEMASK bits (MAVLink common.xml; PX4 mavlink_receiver.cpp handle_message_set_position_target_
# local_ned reads a set bit as "ignore this component")
_IGNORE_VX_VY_VZ = 8 | 16 | 32
_IGNORE_ACC = 64 | 128 | 256
_IGNORE_YAW_RATE = 2048
MASK_POSITION_YAW = _IGNORE_VX_VY_VZ | _IGNORE_ACC | _IGNORE_YAW_RATE  # 2552, as MAVSDK's set_position_ned
MASK_POSITION_VELOCITY_YAW = _IGNORE_ACC | _IGNORE_YAW_RATE  # 2496, as MAVSDK's set_position_velocity_ned
FRAME_LOCAL_NED = 1

STICK_EPS = 1e-3


@dataclass(frozen=True, slots=True)
class Fence:
    """A square of half-width `half_width_m` around home (0 disables it), plus an altitude band above home."""

    home_ned_m: Vec3 = (0.0, 0.0, 0.0)
    half_width_m: float = 5.0
    min_alt_m: float = 0.5
    max_alt_m: float = 10.0

    @property
    def enabled(self) -> bool:
        return self.half_width_m > 0

    def alt_m(self, pos_ned_m: Vec3) -> float:
        """Height above home."""
        return self.home_ned_m[2] - pos_ned_m[2]

    def clamp(self, pos_ned_m: Vec3) -> Vec3:
        x, y, z = pos_ned_m
        hx, hy, hz = self.home_ned_m
        if self.enabled:
            w = self.half_width_m
            x = min(max(x, hx - w), hx + w)
            y = min(max(y, hy - w), hy + w)
        z = min(max(z, hz - self.max_alt_m), hz - self.min_alt_m)
        return (x, y, z)

    def margin_m(self, pos_ned_m: Vec3) -> float:
        """Horizontal distance from the position to the nearest fence side (negative outside; inf if disabled)."""
        if not self.enabled:
            return math.inf
        dx = abs(pos_ned_m[0] - self.home_ned_m[0])
        dy = abs(pos_ned_m[1] - self.home_ned_m[1])
        return self.half_width_m - max(dx, dy)


@dataclass(frozen=True, slots=True)
class Limits:
    """How sticks turn into setpoints (the `joyfly fly` options)."""

    control: str = "velocity"  # "velocity" | "step"
    step_m: float = 2.0
    max_speed_m_s: float = 5.0
    max_climb_m_s: float = 1.0
    max_yaw_rate_rad_s: float = math.radians(45.0)
    leash_m: float = 1.0  # velocity mode: how far the setpoint may run ahead of the vehicle
    brake_acc_m_s2: float = 2.0  # velocity mode: planned deceleration towards the fence
    lag_s: float = 0.5  # how far the vehicle runs on after a stop demand (its velocity lags): hold point, leash
    brake_lookahead_s: float = 0.7  # velocity mode: brake for the fence from where the vehicle will be by then


@dataclass(frozen=True, slots=True)
class Setpoint:
    """One SET_POSITION_TARGET_LOCAL_NED: position, optional velocity feed-forward, yaw."""

    pos_ned_m: Vec3
    yaw_rad: float
    vel_ned_m_s: Vec3 | None = None

    @property
    def type_mask(self) -> int:
        return MASK_POSITION_YAW if self.vel_ned_m_s is None else MASK_POSITION_VELOCITY_YAW


def wrap_pi(angle_rad: float) -> float:
    return (angle_rad + math.pi) % (2 * math.pi) - math.pi


def initial_setpoint(vehicle_ned_m: Vec3, vehicle_yaw_rad: float, fence: Fence, alt_m: float) -> Setpoint:
    """Take-off setpoint: straight above the vehicle at `alt_m` above home, current heading."""
    x, y, _ = vehicle_ned_m
    target = (x, y, fence.home_ned_m[2] - alt_m)
    return Setpoint(fence.clamp(target), wrap_pi(vehicle_yaw_rad))


def hold_setpoint(vehicle_ned_m: Vec3, vehicle_yaw_rad: float, fence: Fence,
                  vehicle_vel_ned_m_s: Vec3 = (0.0, 0.0, 0.0), lag_s: float = 0.0) -> Setpoint:
    """Stop and stay (inside the fence), no feed-forward: at the vehicle's position, or where a moving vehicle
    will be `lag_s` from now (its braking point; PX4's own Hold also brakes to a stop point, navigator/loiter.cpp)."""
    ahead = (vehicle_ned_m[0] + vehicle_vel_ned_m_s[0] * lag_s, vehicle_ned_m[1] + vehicle_vel_ned_m_s[1] * lag_s,
             vehicle_ned_m[2] + vehicle_vel_ned_m_s[2] * lag_s)
    return Setpoint(fence.clamp(ahead), wrap_pi(vehicle_yaw_rad), (0.0, 0.0, 0.0))


def climb_demand(cmd: StickCommand) -> float:
    """-1..1 climb demand: the centred throttle stick, else a non-centring throttle around its middle."""
    if cmd.up is not None:
        return cmd.up
    if cmd.throttle_abs is not None:
        demand = 2.0 * cmd.throttle_abs - 1.0
        return 0.0 if abs(demand) < 0.1 else demand
    return 0.0


def _stick_xy(cmd: StickCommand) -> tuple[float, float]:
    """Horizontal demand with its norm clipped to 1 (a diagonal is no faster than a straight push)."""
    f, r = cmd.forward, cmd.right
    norm = math.hypot(f, r)
    return (f / norm, r / norm) if norm > 1.0 else (f, r)


def next_setpoint(
    prev: Setpoint, cmd: StickCommand, vehicle_ned_m: Vec3, dt_s: float, limits: Limits, fence: Fence,
    vehicle_vel_ned_m_s: Vec3 = (0.0, 0.0, 0.0),
) -> Setpoint:
    """The setpoint after `dt_s` of stick `cmd`, starting from `prev`, clamped by the fence.

    Velocity mode brakes towards a fence side from where the vehicle will be `brake_lookahead_s` from now (position
    plus velocity x lookahead), so a vehicle that lags its demand still stops at the side, not beyond it."""
    yaw = wrap_pi(prev.yaw_rad + cmd.yaw * limits.max_yaw_rate_rad_s * dt_s)
    z = _next_z(prev.pos_ned_m[2], climb_demand(cmd), vehicle_ned_m[2], dt_s, limits)
    if limits.control == "step":
        return _step_xy(prev, cmd, vehicle_ned_m, z, yaw, limits, fence)
    ahead = tuple(p + v * limits.brake_lookahead_s for p, v in zip(vehicle_ned_m, vehicle_vel_ned_m_s, strict=True))
    sp = _velocity_xy(prev, cmd, vehicle_ned_m, (ahead[0], ahead[1]), z, yaw, dt_s, limits, fence)
    return _with_climb_feedforward(sp, z, fence.clamp(sp.pos_ned_m)[2], climb_demand(cmd) * limits.max_climb_m_s)


def _next_z(prev_z: float, climb: float, vehicle_z: float, dt_s: float, limits: Limits) -> float:
    """Integrate the climb demand into the altitude setpoint, kept within a leash of the vehicle."""
    if abs(climb) < STICK_EPS:
        return prev_z
    z = prev_z - climb * limits.max_climb_m_s * dt_s
    return min(max(z, vehicle_z - limits.leash_m), vehicle_z + limits.leash_m)


def _with_climb_feedforward(sp: Setpoint, z_wanted: float, z_clamped: float, climb_m_s: float) -> Setpoint:
    """Vertical feed-forward = the commanded climb (NED: down positive), zero when the altitude band stopped it."""
    if sp.vel_ned_m_s is None or abs(z_wanted - z_clamped) > 1e-9 or abs(climb_m_s) < STICK_EPS:
        return sp
    vx, vy, _ = sp.vel_ned_m_s
    return replace(sp, vel_ned_m_s=(vx, vy, -climb_m_s))


def _step_xy(
    prev: Setpoint, cmd: StickCommand, vehicle: Vec3, z: float, yaw: float, limits: Limits, fence: Fence
) -> Setpoint:
    f, r = _stick_xy(cmd)
    if abs(f) < STICK_EPS and abs(r) < STICK_EPS:
        x, y = prev.pos_ned_m[0], prev.pos_ned_m[1]
    else:
        x, y = vehicle[0] + limits.step_m * f, vehicle[1] + limits.step_m * r
    return Setpoint(fence.clamp((x, y, z)), yaw)


def _brake_limit(v: float, pos: float, centre: float, fence: Fence, acc: float) -> float:
    """Limit speed towards a fence side to sqrt(2 a d): what can still stop at the side."""
    if not fence.enabled or v == 0.0:
        return v
    edge = centre + math.copysign(fence.half_width_m, v)
    room = max(0.0, (edge - pos) * math.copysign(1.0, v))
    return math.copysign(min(abs(v), math.sqrt(2.0 * acc * room)), v)


def _velocity_xy(
    prev: Setpoint,
    cmd: StickCommand,
    vehicle: Vec3,
    ahead: tuple[float, float],
    z: float,
    yaw: float,
    dt_s: float,
    limits: Limits,
    fence: Fence,
) -> Setpoint:
    f, r = _stick_xy(cmd)
    if abs(f) < STICK_EPS and abs(r) < STICK_EPS:
        pos = fence.clamp((prev.pos_ned_m[0], prev.pos_ned_m[1], z))
        return Setpoint(pos, yaw, (0.0, 0.0, 0.0))
    px, py = prev.pos_ned_m[0], prev.pos_ned_m[1]
    hx, hy = fence.home_ned_m[0], fence.home_ned_m[1]
    acc = limits.brake_acc_m_s2
    vx = _brake_limit(limits.max_speed_m_s * f, max(ahead[0], vehicle[0]) if f > 0 else min(ahead[0], vehicle[0]),
                      hx, fence, acc)
    vy = _brake_limit(limits.max_speed_m_s * r, max(ahead[1], vehicle[1]) if r > 0 else min(ahead[1], vehicle[1]),
                      hy, fence, acc)
    leash = min(limits.leash_m, 0.2 + limits.lag_s * math.hypot(vx, vy))  # lead shrinks as the brake bites
    x, y = _leash(px + vx * dt_s - vehicle[0], py + vy * dt_s - vehicle[1], leash)
    pos = fence.clamp((vehicle[0] + x, vehicle[1] + y, z))
    return Setpoint(pos, yaw, (vx, vy, 0.0))


def _leash(dx: float, dy: float, leash_m: float) -> tuple[float, float]:
    dist = math.hypot(dx, dy)
    if dist <= leash_m or dist == 0.0:
        return dx, dy
    return dx * leash_m / dist, dy * leash_m / dist

