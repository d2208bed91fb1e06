"""Multicopter position controller after PX4's PositionControl (src/modules/mc_pos_control/PositionControl/).

Position P -> velocity PID -> acceleration -> thrust vector -> attitude setpoint, with PX4's rules:
- validity (PositionControl.cpp _inputValid): every axis needs a position, velocity or acceleration setpoint, and x/y
  come in pairs for each kind; an invalid setpoint keeps the last valid one for 200 ms, then the failsafe setpoint
  "stop and wait" (zero velocity) of MulticopterPositionControl::failsafe;
- the horizontal velocity limit keeps the position term first (ControlMath::constrainXY);
- vertical anti-windup on thrust saturation, horizontal tracking anti-windup (Rundqwist), vertical integral <= g;
- tilt limit (ControlMath::limitTilt), minimum thrust, and the horizontal margin MPC_THR_XY_MARG.
The velocity derivative for the D term is MulticopterPositionControl's BlockDerivative (low-pass MPC_VELD_LP).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from math import acos, cos, hypot, sin, sqrt
from typing import Final

from sitl_emu.control.qmath import constrain, q_from_dcm_columns
from sitl_emu.params import ParamRegistry
from sitl_emu.types import NAN, NAN3, TrajectorySetpoint, Vec3, Vec4

G: Final = 9.80665  # CONSTANTS_ONE_G
INVALID_HOLD_US: Final = 200_000  # MulticopterPositionControl LOITER_TIME_BEFORE_DESCEND hysteresis
_TWO_PI: Final = 2.0 * math.pi  # (2 pi) fc dt, multiplied left to right as before
# isfinite(x) is written `x - x == 0.0` on the per-tick path: the same for every float (finite: exactly 0.0; inf and
# NaN: NaN) and, unlike a call, plain float arithmetic when compiled by `make speedups` (mypyc has no isfinite).


@dataclass(frozen=True, slots=True)
class PositionControlSettings:
    pos_p: Vec3 = (0.95, 0.95, 1.0)
    vel_p: Vec3 = (1.8, 1.8, 4.0)
    vel_i: Vec3 = (0.4, 0.4, 2.0)
    vel_d: Vec3 = (0.2, 0.2, 0.0)
    thr_hover: float = 0.5
    thr_min: float = 0.12
    thr_max: float = 1.0
    thr_xy_margin: float = 0.3
    vel_max_xy: float = 12.0
    vel_max_up: float = 3.0
    vel_max_dn: float = 1.5
    tilt_max_air_rad: float = math.radians(45.0)
    tilt_max_lnd_rad: float = math.radians(12.0)
    veld_lp_hz: float = 5.0
    use_hte: bool = True

    @classmethod
    def from_params(cls, reg: ParamRegistry) -> PositionControlSettings:
        g = reg.get
        xy_p, xy_vp, xy_vi, xy_vd = g("MPC_XY_P"), g("MPC_XY_VEL_P_ACC"), g("MPC_XY_VEL_I_ACC"), g("MPC_XY_VEL_D_ACC")
        tilt_air = min(g("MPC_TILTMAX_AIR"), 89.0)
        return cls(
            pos_p=(xy_p, xy_p, g("MPC_Z_P")), vel_p=(xy_vp, xy_vp, g("MPC_Z_VEL_P_ACC")),
            vel_i=(xy_vi, xy_vi, g("MPC_Z_VEL_I_ACC")), vel_d=(xy_vd, xy_vd, g("MPC_Z_VEL_D_ACC")),
            thr_hover=constrain(g("MPC_THR_HOVER"), g("MPC_THR_MIN"), g("MPC_THR_MAX")),
            thr_min=g("MPC_THR_MIN"), thr_max=g("MPC_THR_MAX"), thr_xy_margin=g("MPC_THR_XY_MARG"),
            vel_max_xy=g("MPC_XY_VEL_MAX"), vel_max_up=g("MPC_Z_VEL_MAX_UP"), vel_max_dn=g("MPC_Z_VEL_MAX_DN"),
            tilt_max_air_rad=math.radians(tilt_air),
            tilt_max_lnd_rad=math.radians(min(g("MPC_TILTMAX_LND"), tilt_air)),
            veld_lp_hz=g("MPC_VELD_LP"), use_hte=bool(g("MPC_USE_HTE")),
        )


@dataclass(frozen=True, slots=True)
class PositionLimits:
    """Limits for one update (MulticopterPositionControl sets them every cycle)."""

    vel_xy: float = 12.0
    vel_up: float = 3.0  # may be negative at the start of the takeoff ramp
    vel_dn: float = 1.5
    tilt_rad: float = math.radians(45.0)
    thr_min: float = 0.12
    thr_max: float = 1.0


@dataclass(slots=True)
class PositionOutput:
    """One position-control cycle's result. Built on every cycle, so its __init__ is written out: cheaper than a
    NamedTuple's in CPython, and compiled by `make speedups` (mypyc leaves a generated __init__ interpreted)."""

    thrust_ned: Vec3  # normalised thrust vector (z < 0 is up)
    q_sp: Vec4
    collective: float  # |thrust|, 0..1
    yaw_sp_rad: float
    yawspeed_sp_rad_s: float
    in_failsafe: bool
    position_sp_ned_m: Vec3  # the position setpoint used
    velocity_sp_ned_m_s: Vec3  # incl. the P-correction
    acceleration_sp_ned_m_s2: Vec3

    def __init__(self, thrust_ned: Vec3, q_sp: Vec4, collective: float, yaw_sp_rad: float, yawspeed_sp_rad_s: float,
                 in_failsafe: bool, position_sp_ned_m: Vec3, velocity_sp_ned_m_s: Vec3,
                 acceleration_sp_ned_m_s2: Vec3) -> None:
        self.thrust_ned = thrust_ned
        self.q_sp = q_sp
        self.collective = collective
        self.yaw_sp_rad = yaw_sp_rad
        self.yawspeed_sp_rad_s = yawspeed_sp_rad_s
        self.in_failsafe = in_failsafe
        self.position_sp_ned_m = position_sp_ned_m
        self.velocity_sp_ned_m_s = velocity_sp_ned_m_s
        self.acceleration_sp_ned_m_s2 = acceleration_sp_ned_m_s2

    @property
    def local_setpoint(self) -> TrajectorySetpoint:
        """What the controller used, incl. P-corrections (POSITION_TARGET_LOCAL_NED); built on demand."""
        return TrajectorySetpoint(self.position_sp_ned_m, self.velocity_sp_ned_m_s, self.acceleration_sp_ned_m_s2,
                                  self.yaw_sp_rad, self.yawspeed_sp_rad_s)


def input_valid(sp: TrajectorySetpoint) -> bool:
    """PX4 PositionControl::_inputValid (the estimate is always valid here)."""
    p0, p1, p2 = sp.position_ned_m
    v0, v1, v2 = sp.velocity_ned_m_s
    a0, a1, a2 = sp.acceleration_ned_m_s2
    fp0, fv0, fa0 = p0 - p0 == 0.0, v0 - v0 == 0.0, a0 - a0 == 0.0
    fp1, fv1, fa1 = p1 - p1 == 0.0, v1 - v1 == 0.0, a1 - a1 == 0.0
    if not (fp0 or fv0 or fa0) or not (fp1 or fv1 or fa1) or not (p2 - p2 == 0.0 or v2 - v2 == 0.0
                                                                   or a2 - a2 == 0.0):
        return False
    return fp0 == fp1 and fv0 == fv1 and fa0 == fa1


def failsafe_setpoint() -> TrajectorySetpoint:
    """"Failsafe: stop and wait": zero velocity in all axes (the velocity estimate is always valid here)."""
    return TrajectorySetpoint(velocity_ned_m_s=(0.0, 0.0, 0.0))


def constrain_xy(v0x: float, v0y: float, v1x: float, v1y: float, vmax: float) -> tuple[float, float]:
    """ControlMath::constrainXY: limit |v0 + v1| to vmax, keeping as much of v0 as possible."""
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
    ux, uy = v1x / n1, v1y / n1
    m = ux * v0x + uy * v0y
    c = v0x * v0x + v0y * v0y - vmax * vmax
    s = -m + sqrt(m * m - c)
    return v0x + ux * s, v0y + uy * s


def limit_tilt(bz: Vec3, max_angle_rad: float) -> Vec3:
    """ControlMath::limitTilt against the world z axis (0, 0, 1)."""
    d = constrain(bz[2], -1.0, 1.0)
    angle = acos(d)
    angle = max_angle_rad if max_angle_rad < angle else angle  # min(acos(d), max_angle_rad)
    rx, ry = bz[0], bz[1]
    rn = hypot(rx, ry)
    if rn * rn < 1.2e-7:  # FLT_EPSILON
        rx, ry, rn = 1.0, 0.0, 1.0
    s = sin(angle)
    return s * rx / rn, s * ry / rn, cos(angle)


def bodyz_to_attitude(bz: Vec3, yaw_rad: float) -> Vec4:
    """ControlMath::bodyzToAttitude: attitude with body z along bz (world frame) and the given heading.

    Written on scalars, it runs every position cycle: qmath's normalized, cross and (for a positive trace, the
    usual case) q_from_dcm_columns with q_normalized are inlined in their operation order, zero components kept."""
    z0, z1, z2 = bz
    if z0 * z0 + z1 * z1 + z2 * z2 < 1.2e-7:
        z0, z1, z2 = 0.0, 0.0, 1.0
    n = sqrt(z0 * z0 + z1 * z1 + z2 * z2)
    if n > 0.0:
        z0, z1, z2 = z0 / n, z1 / n, z2 / n
    else:
        z0 = z1 = z2 = 0.0
    y0, y1, y2 = -sin(yaw_rad), cos(yaw_rad), 0.0
    x0, x1, x2 = y1 * z2 - y2 * z1, y2 * z0 - y0 * z2, y0 * z1 - y1 * z0  # cross(y_c, bz)
    if z2 < 0.0:
        x0, x1, x2 = -x0, -x1, -x2
    if abs(z2) < 1e-6:
        x0, x1, x2 = 0.0, 0.0, 1.0
    n = sqrt(x0 * x0 + x1 * x1 + x2 * x2)
    if n > 0.0:
        x0, x1, x2 = x0 / n, x1 / n, x2 / n
    else:
        x0 = x1 = x2 = 0.0
    b0, b1, b2 = z1 * x2 - z2 * x1, z2 * x0 - z0 * x2, z0 * x1 - z1 * x0  # by = cross(bz, bx)
    tr = x0 + b1 + z2
    if not tr > 0.0:
        return q_from_dcm_columns((x0, x1, x2), (b0, b1, b2), (z0, z1, z2))
    s = sqrt(tr + 1.0)
    w = 0.5 * s
    s = 0.5 / s
    qx, qy, qz = (b2 - z1) * s, (z0 - x2) * s, (x1 - b0) * s
    n = sqrt(w * w + qx * qx + qy * qy + qz * qz)
    if not n > 0.0:
        return 1.0, 0.0, 0.0, 0.0
    return w / n, qx / n, qy / n, qz / n


class VelocityDerivative:
    """controllib BlockDerivative: finite difference through a first-order low-pass (MPC_VELD_LP)."""

    def __init__(self) -> None:
        self._prev: Vec3 | None = None
        self._out: Vec3 = (0.0, 0.0, 0.0)

    def reset(self) -> None:
        self._prev = None
        self._out = (0.0, 0.0, 0.0)

    def update(self, vel: Vec3, dt_s: float, cutoff_hz: float) -> Vec3:
        if self._prev is None or dt_s <= 0.0:
            self._prev = vel
            return self._out
        b = _TWO_PI * cutoff_hz * dt_s
        a = b / (1.0 + b) if cutoff_hz > 0.0 else 1.0
        o0, o1, o2 = self._out
        p0, p1, p2 = self._prev
        v0, v1, v2 = vel
        self._out = (o0 + a * ((v0 - p0) / dt_s - o0), o1 + a * ((v1 - p1) / dt_s - o1),
                     o2 + a * ((v2 - p2) / dt_s - o2))
        self._prev = vel
        return self._out


class PositionControl:
    """One instance per vehicle; `update` is pure apart from the integrator, filter and failsafe memory."""

    def __init__(self, settings: PositionControlSettings | None = None) -> None:
        self.settings = settings or PositionControlSettings()
        self.hover_thrust = self.settings.thr_hover
        self._vel_int: list[float] = [0.0, 0.0, 0.0]
        self._deriv = VelocityDerivative()
        self._last_valid: TrajectorySetpoint | None = None
        self._invalid_since_us: int | None = None

    def reset(self) -> None:
        self.reset_integral()
        self._deriv.reset()
        self._last_valid = None
        self._invalid_since_us = None

    def reset_integral(self) -> None:
        self._vel_int = [0.0, 0.0, 0.0]

    def set_hover_thrust(self, hover: float) -> None:
        self.hover_thrust = hover

    def update_hover_thrust(self, hover_new: float, acc_sp_z: float) -> None:
        """PositionControl::updateHoverThrust: change the hover thrust without a thrust step (integrator absorbs)."""
        if hover_new > 1.2e-7:
            self._vel_int[2] += (acc_sp_z - G) * self.hover_thrust / hover_new + G - acc_sp_z
            self.hover_thrust = hover_new

    def select_setpoint(self, sp: TrajectorySetpoint, now_us: int) -> tuple[TrajectorySetpoint, bool]:
        """The setpoint to fly: sp if valid, else the last valid one for 200 ms, else the failsafe setpoint."""
        if sp is self._last_valid or input_valid(sp):  # the last valid setpoint (immutable) is still valid
            self._last_valid, self._invalid_since_us = sp, None
            return sp, False
        if self._invalid_since_us is None:
            self._invalid_since_us = now_us
        if self._last_valid is not None and now_us - self._invalid_since_us < INVALID_HOLD_US:
            return self._last_valid, False
        return failsafe_setpoint(), True

    def update(self, pos: Vec3, vel: Vec3, yaw_rad: float, sp: TrajectorySetpoint, limits: PositionLimits,
               dt_s: float, now_us: int) -> PositionOutput:
        return self.update_with(pos, vel, yaw_rad, sp, dt_s, now_us, limits.vel_xy, limits.vel_up, limits.vel_dn,
                                limits.tilt_rad, limits.thr_min, limits.thr_max)

    def update_with(self, pos: Vec3, vel: Vec3, yaw_rad: float, sp: TrajectorySetpoint, dt_s: float, now_us: int,
                    vel_xy: float, vel_up: float, vel_dn: float, tilt_rad: float, thr_min: float,
                    thr_max: float) -> PositionOutput:
        """`update` with the PositionLimits fields passed as floats (the cascade's path: no limits object)."""
        vel_dot = self._deriv.update(vel, dt_s, self.settings.veld_lp_hz)
        if sp is self._last_valid:  # select_setpoint's answer for the same (immutable, valid) setpoint object
            self._invalid_since_us, in_failsafe = None, False
        else:
            sp, in_failsafe = self.select_setpoint(sp, now_us)
        vel_sp = self._position_control(pos, sp, vel_xy, vel_up, vel_dn)
        acc_sp, thr = self._velocity_control(vel, vel_dot, vel_sp, sp.acceleration_ned_m_s2, tilt_rad, thr_min,
                                             thr_max, dt_s)
        yaw_sp, yawspeed = sp.yaw_rad, sp.yawspeed_rad_s
        yaw_sp = yaw_sp if yaw_sp - yaw_sp == 0.0 else yaw_rad
        yawspeed = yawspeed if yawspeed - yawspeed == 0.0 else 0.0
        t0, t1, t2 = thr
        collective = sqrt(t0 * t0 + t1 * t1 + t2 * t2)
        q_sp = bodyz_to_attitude((-t0, -t1, -t2), yaw_sp)
        return PositionOutput(thr, q_sp, collective, yaw_sp, yawspeed, in_failsafe, sp.position_ned_m, vel_sp, acc_sp)

    def _position_control(self, pos: Vec3, sp: TrajectorySetpoint, vel_xy: float, vel_up: float,
                          vel_dn: float) -> Vec3:
        k0, k1, k2 = self.settings.pos_p
        p0, p1, p2 = sp.position_ned_m
        f0, f1, f2 = sp.velocity_ned_m_s
        x0, x1, x2 = pos
        v0, v1, v2 = (p0 - x0) * k0, (p1 - x1) * k1, (p2 - x2) * k2  # NaN where not controlled
        # ControlMath::addIfNotNan(feed-forward, P term)
        s0 = (f0 + v0 if v0 - v0 == 0.0 else f0) if f0 - f0 == 0.0 else v0
        s1 = (f1 + v1 if v1 - v1 == 0.0 else f1) if f1 - f1 == 0.0 else v1
        s2 = (f2 + v2 if v2 - v2 == 0.0 else f2) if f2 - f2 == 0.0 else v2
        v0 = v0 if v0 - v0 == 0.0 else 0.0
        v1 = v1 if v1 - v1 == 0.0 else 0.0
        vx, vy = constrain_xy(v0, v1, s0 - v0, s1 - v1, vel_xy)
        lo = -vel_up
        return vx, vy, lo if s2 < lo else (vel_dn if s2 > vel_dn else s2)

    def _velocity_control(self, vel: Vec3, vel_dot: Vec3, vel_sp: Vec3, acc_ff: Vec3, tilt_rad: float,
                          thr_min: float, thr_max: float, dt_s: float) -> tuple[Vec3, Vec3]:
        """Velocity PID -> acceleration -> thrust, with the anti-windups; flat on scalars (the hot path)."""
        s = self.settings
        kp0, kp1, kp2 = s.vel_p
        kd0, kd1, kd2 = s.vel_d
        integ = self._vel_int
        e0, e1, e2 = vel_sp[0] - vel[0], vel_sp[1] - vel[1], vel_sp[2] - vel[2]
        f0, f1, f2 = acc_ff
        a0 = e0 * kp0 + integ[0] - vel_dot[0] * kd0
        a1 = e1 * kp1 + integ[1] - vel_dot[1] * kd1
        a2 = e2 * kp2 + integ[2] - vel_dot[2] * kd2
        a0 = (f0 + a0 if a0 - a0 == 0.0 else f0) if f0 - f0 == 0.0 else a0  # addIfNotNan(feed-forward, PID)
        a1 = (f1 + a1 if a1 - a1 == 0.0 else f1) if f1 - f1 == 0.0 else a1
        a2 = (f2 + a2 if a2 - a2 == 0.0 else f2) if f2 - f2 == 0.0 else a2
        # acceleration -> thrust: body z = limit_tilt(normalized((-a0, -a1, G)), tilt_rad), inlined
        z0, z1 = -a0, -a1
        n = sqrt(z0 * z0 + z1 * z1 + G * G)
        if n > 0.0:
            z0, z1, z2 = z0 / n, z1 / n, G / n
        else:
            z0 = z1 = z2 = 0.0
        z2 = -1.0 if z2 < -1.0 else (1.0 if z2 > 1.0 else z2)
        angle = acos(z2)
        angle = tilt_rad if tilt_rad < angle else angle  # min(acos(z), tilt_rad)
        rn = hypot(z0, z1)
        if rn * rn < 1.2e-7:  # FLT_EPSILON
            z0, z1, rn = 1.0, 0.0, 1.0
        sn = sin(angle)
        z0, z1, z2 = sn * z0 / rn, sn * z1 / rn, cos(angle)
        h = self.hover_thrust
        c = (a2 * (h / G) - h) / z2
        tmin = 10e-4 if thr_min < 10e-4 else thr_min  # max(thr_min, 10e-4)
        c = -tmin if -tmin < c else c  # min(c, -tmin)
        t0, t1, t2 = z0 * c, z1 * c, z2 * c
        if (t2 >= -tmin and e2 >= 0.0) or (t2 <= -thr_max and e2 <= 0.0):
            e2 = 0.0  # vertical anti-windup
        # saturation: prioritise vertical thrust but keep MPC_THR_XY_MARG for horizontal control
        xy = hypot(t0, t1)
        tmax2 = thr_max * thr_max
        margin = s.thr_xy_margin
        allocated_xy = margin if margin < xy else xy  # min(xy, margin)
        rem = tmax2 - allocated_xy * allocated_xy
        lo = -sqrt(0.0 if rem < 0.0 else rem)  # -sqrt(max(rem, 0))
        t2 = lo if lo > t2 else t2  # max(t2, lo)
        rem = tmax2 - t2 * t2
        xy_max = sqrt(0.0 if rem < 0.0 else rem)
        if xy > xy_max:
            t0, t1 = t0 / xy * xy_max, t1 / xy * xy_max
        # horizontal tracking anti-windup: feed back the part of the demand the thrust could not produce
        k = G / h
        prod_x, prod_y = t0 * k, t1 * k
        if a0 * a0 + a1 * a1 > prod_x * prod_x + prod_y * prod_y:
            arw = 2.0 / kp0
            e0 -= arw * (a0 - prod_x)
            e1 -= arw * (a1 - prod_y)
        ki0, ki1, ki2 = s.vel_i
        if e0 - e0 == 0.0:
            integ[0] += e0 * ki0 * dt_s
        if e1 - e1 == 0.0:
            integ[1] += e1 * ki1 * dt_s
        if e2 - e2 == 0.0:
            integ[2] += e2 * ki2 * dt_s
        i2 = integ[2]
        integ[2] = -G if i2 < -G else (G if i2 > G else i2)
        return (a0, a1, a2), (t0, t1, t2)


__all__ = ["NAN", "NAN3", "PositionControl", "PositionControlSettings", "PositionLimits", "PositionOutput"]
