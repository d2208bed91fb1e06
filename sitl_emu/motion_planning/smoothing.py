"""Jerk- and acceleration-limited trajectories, after PX4's motion_planning library.

Written from the behaviour of PX4's `src/lib/motion_planning/VelocitySmoothing.cpp` (one axis: constant-jerk
segments T1 (jerk up), T2 (constant acceleration), T3 (jerk down) that bring the velocity to a target),
`PositionSmoothing.cpp` (a velocity target per axis derived from the distance to a waypoint, the time stretch that
waits for a lagging vehicle), `src/lib/mathlib/math/TrajMath.hpp` (speed from braking distance, speed allowed in a
turn) and `src/lib/motion_planning/TrajectoryConstraints.hpp` (the speed allowed at a waypoint from the angle to the
next leg).

Two entries: `update` flies to one waypoint (Hold, Takeoff, Land, RTL, reposition: PX4 passes previous = current =
next there, which reduces its path case to this), `update_path` flies a mission leg with the previous and next
waypoints: the speed at the waypoint is limited by the turn to the next leg, and while the trajectory turns it is
pulled towards an L1-like crossing point on the line from the previous waypoint (PositionSmoothing::_getL1Point).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final

from sitl_emu.control.qmath import acos, all_finite3, constrain, hypot, isfinite
from sitl_emu.types import Vec3

_EPS: Final = 1.1920929e-07  # FLT_EPSILON, as PX4 compares with it


def max_speed_from_distance(jerk: float, accel: float, distance_m: float, final_speed: float) -> float:
    """Largest speed from which the vehicle can slow to `final_speed` within `distance_m` (TrajMath.hpp)."""
    b = 4.0 * accel * accel / jerk
    c = -2.0 * accel * distance_m - final_speed * final_speed
    speed = 0.5 * (-b + math.sqrt(b * b - 4.0 * c))
    return max(speed, final_speed)


def braking_distance(speed: float, jerk: float, accel: float, accel_delay_max: float) -> float:
    """Distance to stop from `speed` (TrajMath.hpp computeBrakingDistanceFromVelocity)."""
    return speed * (speed / (2.0 * accel) + accel_delay_max / jerk)


def _sign(x: float) -> int:
    return (x > 0.0) - (x < 0.0)


def speed_in_turn(alpha: float, accel: float, radius: float) -> float:
    """Speed at a waypoint whose legs meet at angle `alpha` (pi: straight on), turning on a circle tangent to both
    legs at the acceptance radius (TrajMath.hpp computeMaxSpeedInWaypoint)."""
    return math.sqrt(accel * radius * math.tan(alpha / 2.0))


def _angle(a: tuple[float, float], b: tuple[float, float]) -> float:
    """The angle between two 2D vectors (a zero vector counts as orthogonal, as unit_or_zero makes it)."""
    na, nb = hypot(a[0], a[1]), hypot(b[0], b[1])
    if na <= _EPS or nb <= _EPS:
        return math.pi / 2.0
    return acos(max(-1.0, min(1.0, (a[0] * b[0] + a[1] * b[1]) / (na * nb))))


@dataclass(frozen=True, slots=True)
class _Limits:
    """TrajectoryConstraints' VehicleDynamicLimits (the horizontal part)."""

    accept_xy: float
    accel: float
    jerk: float
    cruise: float
    gain: float  # MPC_XY_TRAJ_P: the share of the acceleration used in turns


def _start_speed(start: Vec3, target: Vec3, following: Vec3, exit_speed: float, lim: _Limits) -> float:
    """Fastest speed at `start` that still makes the turn at `target` towards `following`
    (TrajectoryConstraints.hpp computeStartXYSpeedFromWaypoints)."""
    leg_next = hypot(target[0] - following[0], target[1] - following[1])
    at_target = 0.0
    if leg_next > 0.001 and leg_next >= lim.accept_xy:  # different points, the next outside the acceptance radius
        alpha = _angle((target[0] - start[0], target[1] - start[1]),
                       (target[0] - following[0], target[1] - following[1]))
        turn = speed_in_turn(min(max(alpha, 0.0), math.pi - _EPS), lim.gain * lim.accel, lim.accept_xy)
        at_target = min(turn, exit_speed, lim.cruise)
    dist = hypot(start[0] - target[0], start[1] - target[1])
    return min(lim.cruise, max_speed_from_distance(lim.jerk, lim.accel, dist, at_target))


def xy_speed_through(pos: Vec3, target: Vec3, following: Vec3, lim: _Limits) -> float:
    """computeXYSpeedFromWaypoints over (pos, target, following): backwards from a stop at `following`."""
    exit_speed = _start_speed(target, following, following, 0.0, lim)
    return _start_speed(pos, target, following, exit_speed, lim)


def _evaluate_poly(j: float, a0: float, v0: float, x0: float, t: float) -> tuple[float, float, float, float]:
    """(jerk, acceleration, velocity, position) after t seconds of constant jerk j (VelocitySmoothing::evaluatePoly;
    update_traj never passes a negative t)."""
    return j, a0 + j * t, v0 + a0 * t + 0.5 * j * t * t, x0 + v0 * t + 0.5 * a0 * t * t + j * t * t * t / 6.0


class AxisSmoother:
    """One axis of a jerk-limited trajectory (state: jerk, acceleration, velocity, position)."""

    __slots__ = ("_a0", "_dir", "_t1", "_t2", "_t3", "_time", "_v0", "_vel_sp", "_x0",
                 "a", "j", "max_accel", "max_jerk", "max_vel", "v", "x")

    def __init__(self, accel: float = 0.0, vel: float = 0.0, pos: float = 0.0) -> None:
        self.max_jerk, self.max_accel, self.max_vel = 4.0, 3.0, 12.0
        self._t1 = self._t2 = self._t3 = 0.0
        self._dir = 0
        self._vel_sp = 0.0
        self.reset(accel, vel, pos)

    def reset(self, accel: float, vel: float, pos: float) -> None:
        self.j, self.a, self.v, self.x = 0.0, accel, vel, pos
        self._a0, self._v0, self._x0 = accel, vel, pos
        self._time = 0.0
        self._t1 = self._t2 = self._t3 = 0.0

    def set_position(self, pos: float) -> None:
        self.x = self._x0 = pos

    @property
    def total_time(self) -> float:
        return self._t1 + self._t2 + self._t3

    def update_durations(self, vel_setpoint: float) -> None:
        """Plan the fastest jerk-limited profile from the current state to `vel_setpoint` (clamped to max_vel)."""
        vel_sp = self._vel_sp = constrain(vel_setpoint, -self.max_vel, self.max_vel)
        self._time = 0.0
        a, v = self.a, self.v
        self._a0, self._v0, self._x0 = a, v, self.x
        if a == 0.0 and v == vel_sp:  # steady: nothing to plan
            self._dir = 0
            self._t1 = self._t2 = self._t3 = 0.0
            return
        # the jerk direction: towards vel_sp from the velocity reached once the acceleration is brought to zero
        vel_zero_acc = v
        if abs(a) > _EPS:
            j_zero = -_sign(a) * self.max_jerk
            t_zero = -a / j_zero
            vel_zero_acc = v + a * t_zero + 0.5 * j_zero * t_zero * t_zero
        direction = _sign(vel_sp - vel_zero_acc)
        if direction == 0:
            direction = _sign(a)
        self._dir = direction
        jerk = direction * self.max_jerk
        if abs(jerk) <= _EPS:
            self._t1 = self._t2 = self._t3 = 0.0
            return
        dv = vel_sp - v
        t1 = self._t1 = self._t1_min_time(a, dv, jerk)
        t3 = self._t3 = max(a / jerk + t1, 0.0)
        # T2 from the velocity the jerk phases leave to the constant-acceleration phase
        den = a + jerk * t1
        if abs(den) <= _EPS:
            self._t2 = 0.0
            return
        t2 = (-0.5 * t1 * t1 * jerk - t1 * t3 * jerk - t1 * a + 0.5 * t3 * t3 * jerk - t3 * a + dv) / den
        self._t2 = max(t2, 0.0)

    def update_durations_given_total_time(self, total_s: float) -> None:
        """Stretch the current plan so that it lasts `total_s` (used to synchronise the axes)."""
        jerk = self._dir * self.max_jerk
        if abs(jerk) <= _EPS:
            self._t1 = self._t2 = self._t3 = 0.0
            return
        t1 = self._t1 = self._t1_given_total(total_s, self.a, self._vel_sp - self.v, jerk)
        t3 = self._t3 = max(self.a / jerk + t1, 0.0)
        self._t2 = max(total_s - t1 - t3, 0.0)

    def update_traj(self, dt_s: float, time_stretch: float = 1.0) -> None:
        """Advance along the planned profile by `dt_s` (>= 0) scaled by `time_stretch` (0..1)
        (VelocitySmoothing::updateTraj): T1 at +jerk, T2 at constant acceleration, T3 at -jerk, then constant
        velocity."""
        rest = self._time = self._time + dt_s * time_stretch
        if self._t1 == 0.0 and self._t2 == 0.0 and self._t3 == 0.0:  # nothing planned: constant velocity
            if rest > 0.0:
                self.j, self.a, self.v, self.x = 0.0, 0.0, self._v0, self._x0 + self._v0 * rest
            else:
                self.j, self.a, self.v, self.x = 0.0, self._a0, self._v0, self._x0
            return
        j, a, v, x = _evaluate_poly(self._dir * self.max_jerk, self._a0, self._v0, self._x0, min(rest, self._t1))
        rest -= self._t1
        if rest > 0.0:
            j, a, v, x = _evaluate_poly(0.0, a, v, x, min(rest, self._t2))
            rest -= self._t2
        if rest > 0.0:
            j, a, v, x = _evaluate_poly(-self._dir * self.max_jerk, a, v, x, min(rest, self._t3))
            rest -= self._t3
        if rest > 0.0:
            j, a, v, x = _evaluate_poly(0.0, 0.0, v, x, rest)
        self.j, self.a, self.v, self.x = j, a, v, x

    def _saturate_t1(self, a0: float, jerk: float, t1: float) -> float:
        accel_t1 = a0 + jerk * t1
        if accel_t1 > self.max_accel:
            return (self.max_accel - a0) / jerk
        if accel_t1 < -self.max_accel:
            return (-self.max_accel - a0) / jerk
        return t1

    def _t1_min_time(self, a0: float, dv: float, jerk: float) -> float:
        delta = 2.0 * a0 * a0 + 4.0 * jerk * dv
        if delta < 0.0:
            return 0.0
        root = math.sqrt(delta)
        t1 = 0.0
        cand = (-a0 + 0.5 * root) / jerk
        if cand >= 0.0 and a0 / jerk + cand >= 0.0:
            t1 = cand
        else:
            cand = (-a0 - 0.5 * root) / jerk
            if cand >= 0.0 and a0 / jerk + cand >= 0.0:
                t1 = cand
        return max(self._saturate_t1(a0, jerk, t1), 0.0)

    def _t1_given_total(self, total: float, a0: float, dv: float, jerk: float) -> float:
        qa, qb = -jerk, jerk * total - a0
        delta = total * total * jerk * jerk + 2.0 * total * a0 * jerk - a0 * a0 - 4.0 * jerk * dv
        if delta < 0.0:
            return 0.0
        root = math.sqrt(delta)
        t1 = 0.0
        cand = max((-qb + root) / (2.0 * qa), 0.0)
        t3 = a0 / jerk + cand
        if t3 >= 0.0 and cand + t3 <= total:
            t1 = cand
        else:
            cand = max((-qb - root) / (2.0 * qa), 0.0)
            t3 = a0 / jerk + cand
            if t3 >= 0.0 and cand + t3 <= total:
                t1 = cand
        return self._saturate_t1(a0, jerk, t1)


def synchronize(x: AxisSmoother, y: AxisSmoother, z: AxisSmoother) -> None:
    """Make every axis finish its velocity change together with the slowest one
    (VelocitySmoothing::timeSynchronization). Three named axes, not a list: mypyc keeps their times unboxed."""
    tx, ty, tz = x.total_time, y.total_time, z.total_time  # each read before its own axis changes
    desired = ty if ty > tx else tx  # the longest, the first of equals (PX4's scan)
    desired = tz if tz > desired else desired
    if desired <= _EPS:
        return
    if tx < desired:  # the longest axis keeps its plan
        x.update_durations_given_total_time(desired)
    if ty < desired:
        y.update_durations_given_total_time(desired)
    if tz < desired:
        z.update_durations_given_total_time(desired)


class PositionSmoother:
    """Three jerk-limited axes driven towards one waypoint (PX4 PositionSmoothing, single-waypoint case).

    Limits are public attributes the caller sets before each `update` (as FlightTaskAuto does every cycle); the
    axes hold the smoothed setpoint (x, v, a) after it.
    """

    def __init__(self, accel: Vec3, vel: Vec3, pos: Vec3) -> None:
        self.axes = [AxisSmoother(accel[i], vel[i], pos[i]) for i in range(3)]
        self.cruise_speed_m_s = 5.0
        self.max_xy_error_m = 2.0
        self.max_z_error_m = 0.0  # 0 disables the vertical time stretch
        # path flying (update_path): the waypoint's acceptance radii and MPC_XY_TRAJ_P
        self.acceptance_xy_m = 0.0
        self.acceptance_z_m = 0.0
        self.traj_gain = 0.5
        self._max_speed_previous = 0.0

    def reset(self, accel: Vec3, vel: Vec3, pos: Vec3) -> None:
        ax, ay, az = self.axes  # named: an index that varies would box the vectors' floats
        ax.reset(accel[0], vel[0], pos[0])
        ay.reset(accel[1], vel[1], pos[1])
        az.reset(accel[2], vel[2], pos[2])

    def set_limits(self, jerk: float, accel_xy: float, accel_z: float, vel_xy: float, vel_z: float) -> None:
        ax, ay, az = self.axes
        ax.max_jerk, ax.max_accel, ax.max_vel = jerk, accel_xy, vel_xy
        ay.max_jerk, ay.max_accel, ay.max_vel = jerk, accel_xy, vel_xy
        az.max_jerk, az.max_accel, az.max_vel = jerk, accel_z, vel_z

    def update(self, vehicle_pos: Vec3, target: Vec3, feedforward_vel: Vec3, dt_s: float,
               force_zero_velocity: bool = False) -> Vec3:
        """One cycle: target xy (pair) and/or z may be NaN (then the feed-forward velocity drives that axis).
        The axes hold the new setpoint; returns the unsmoothed velocity target (zero when `force_zero_velocity`:
        PositionSmoothing::generateSetpoints brakes to a stop)."""
        vel_sp = (0.0, 0.0, 0.0) if force_zero_velocity else self._velocity_target(target, feedforward_vel)
        if all_finite3(vel_sp):
            self._advance(vehicle_pos, vel_sp, dt_s)
        return vel_sp

    def update_path(self, vehicle_pos: Vec3, previous: Vec3, target: Vec3, following: Vec3, dt_s: float,
                    force_zero_velocity: bool = False) -> Vec3:
        """One cycle along a path (all three waypoints finite; `following` = `target` when there is no next one).
        Returns the unsmoothed velocity target (PositionSmoothing::_generateVelocitySetpoint, 3D case)."""
        if force_zero_velocity:
            return self.update(vehicle_pos, target, (0.0, 0.0, 0.0), dt_s, force_zero_velocity=True)
        pos = self.position
        turning = self._is_turning(target)
        crossing = self._l1_point(previous, target) if turning else target
        xy_speed = xy_speed_through(pos, target, following, self._limits())
        if turning:
            xy_speed = min(self._max_speed_previous, xy_speed)  # hold the speed through a turn
        else:
            self._max_speed_previous = xy_speed
        dx, dy = crossing[0] - pos[0], crossing[1] - pos[1]
        dist = hypot(dx, dy)
        ux, uy = (dx / dist, dy / dist) if dist > 1e-6 else (0.0, 0.0)
        vel_sp = (ux * xy_speed, uy * xy_speed, _sign(crossing[2] - pos[2]) * self._z_speed(pos, target, following))
        self._advance(vehicle_pos, vel_sp, dt_s)
        return vel_sp

    @property
    def position(self) -> Vec3:
        ax, ay, az = self.axes
        return (ax.x, ay.x, az.x)

    def _limits(self) -> _Limits:
        ax = self.axes[0]
        return _Limits(self.acceptance_xy_m, ax.max_accel, ax.max_jerk, self.cruise_speed_m_s, self.traj_gain)

    def _is_turning(self, target: Vec3) -> bool:
        """The trajectory moves (> 0.2 m/s) more than ~10 degrees away from the target, outside its acceptance
        radius (PositionSmoothing::_isTurning)."""
        ax, ay = self.axes[0], self.axes[1]
        speed = hypot(ax.v, ay.v)
        tx, ty = target[0] - ax.x, target[1] - ay.x
        dist = hypot(tx, ty)
        if speed <= 0.2 or dist <= self.acceptance_xy_m:
            return False
        cos_align = (ax.v * tx + ay.v * ty) / (speed * dist) if dist > 0.0 else 0.0
        return cos_align < 0.98

    def _l1_point(self, previous: Vec3, target: Vec3) -> Vec3:
        """Where a circle of radius max(acceptance, 5 m) around the trajectory meets the line previous -> target,
        ahead of the closest point (PositionSmoothing::_getL1Point)."""
        pos = self.position
        leg = (target[0] - previous[0], target[1] - previous[1], target[2] - previous[2])
        length = math.sqrt(leg[0] ** 2 + leg[1] ** 2 + leg[2] ** 2)
        u = (leg[0] / length, leg[1] / length, leg[2] / length) if length > 1e-6 else (0.0, 0.0, 0.0)
        along = sum((pos[i] - previous[i]) * u[i] for i in range(3))
        closest = tuple(previous[i] + u[i] * along for i in range(3))
        cross = math.sqrt(sum((closest[i] - pos[i]) ** 2 for i in range(3)))
        l1 = max(self.acceptance_xy_m, 5.0)
        ahead = math.sqrt(l1 * l1 - cross * cross) if l1 > cross else 0.0
        return (closest[0] + ahead * u[0], closest[1] + ahead * u[1], closest[2] + ahead * u[2])

    def _z_speed(self, pos: Vec3, target: Vec3, following: Vec3) -> float:
        """PositionSmoothing::_getMaxZSpeed: arrive at the target's altitude at the speed the vertical turn allows
        (0 when the next leg is level)."""
        az = self.axes[2]
        arrival = 0.0
        if abs(target[2] - following[2]) > 0.001:
            # PX4 pairs each point's horizontal distance from the origin with its altitude
            start = (hypot(pos[0], pos[1]), pos[2])
            tgt = (hypot(target[0], target[1]), target[2])
            nxt = (hypot(following[0], following[1]), following[2])
            alpha = _angle((tgt[0] - start[0], tgt[1] - start[1]), (tgt[0] - nxt[0], tgt[1] - nxt[1]))
            turn = speed_in_turn(min(max(alpha, 0.0), math.pi - _EPS), az.max_accel, self.acceptance_z_m)
            arrival = min(turn, az.max_vel)
        reach = max_speed_from_distance(az.max_jerk, az.max_accel, abs(target[2] - pos[2]), arrival)
        return min(az.max_vel, reach)

    def _velocity_target(self, target: Vec3, ff: Vec3) -> Vec3:
        out0, out1, out2 = ff
        ax, ay, az = self.axes
        if isfinite(target[0]) and isfinite(target[1]):
            dx, dy = target[0] - ax.x, target[1] - ay.x
            dist = hypot(dx, dy)
            speed = min(self.cruise_speed_m_s, max_speed_from_distance(ax.max_jerk, ax.max_accel, dist, 0.0))
            ux, uy = (dx / dist, dy / dist) if dist > 1e-6 else (0.0, 0.0)
            out0 = ux * speed + (ff[0] if isfinite(ff[0]) else 0.0)
            out1 = uy * speed + (ff[1] if isfinite(ff[1]) else 0.0)
        if isfinite(target[2]):
            dz = target[2] - az.x
            speed = min(az.max_vel, max_speed_from_distance(az.max_jerk, az.max_accel, abs(dz), 0.0))
            out2 = _sign(dz) * speed + (ff[2] if isfinite(ff[2]) else 0.0)
        return (out0, out1, out2)

    def _advance(self, vehicle_pos: Vec3, vel_sp: Vec3, dt_s: float) -> None:
        stretch_xy = self._stretch_xy(vehicle_pos)
        stretch_z = 1.0 if self.max_z_error_m <= _EPS else self._stretch_z(vehicle_pos)
        ax, ay, az = self.axes
        ax.update_traj(dt_s, stretch_xy)
        ay.update_traj(dt_s, stretch_xy)
        az.update_traj(dt_s, stretch_z)
        ax.update_durations(vel_sp[0])
        ay.update_durations(vel_sp[1])
        az.update_durations(vel_sp[2])
        synchronize(ax, ay, az)

    def _stretch_xy(self, vehicle_pos: Vec3) -> float:
        """Slow the trajectory while the vehicle lags behind it (PositionSmoothing::_generateTrajectory)."""
        ax, ay = self.axes[0], self.axes[1]
        ex, ey = ax.x - vehicle_pos[0], ay.x - vehicle_pos[1]
        if self.max_xy_error_m <= _EPS or ex * ax.v + ey * ay.v < 0.0:
            return 1.0
        return 1.0 - constrain(hypot(ex, ey) / self.max_xy_error_m, 0.0, 1.0)

    def _stretch_z(self, vehicle_pos: Vec3) -> float:
        ez = self.axes[2].x - vehicle_pos[2]
        if self.max_z_error_m <= _EPS or ez * self.axes[2].v < 0.0:
            return 1.0
        return 1.0 - min(abs(ez) / self.max_z_error_m, 1.0)
