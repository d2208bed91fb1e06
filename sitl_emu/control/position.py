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

from sitl_emu.control.qmath import constrain, cross, normalized, q_from_dcm_columns
from sitl_emu.params import ParamRegistry
from sitl_emu.types import NAN, NAN3, TrajectorySetpoint, Vec3, Vec4

G = 9.80665  # CONSTANTS_ONE_G
INVALID_HOLD_US = 200_000  # MulticopterPositionControl LOITER_TIME_BEFORE_DESCEND hysteresis
_isfinite = math.isfinite


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


@dataclass(frozen=True, slots=True)
class PositionOutput:
    thrust_ned: Vec3  # normalised thrust vector (z < 0 is up)
    q_sp: Vec4
    collective: float  # |thrust|, 0..1
    yaw_sp_rad: float
    yawspeed_sp_rad_s: float
    local_setpoint: TrajectorySetpoint  # what the controller used, incl. P-corrections (POSITION_TARGET_LOCAL_NED)
    in_failsafe: bool


def input_valid(sp: TrajectorySetpoint) -> bool:
    """PX4 PositionControl::_inputValid (the estimate is always valid here)."""
    p, v, a = sp.position_ned_m, sp.velocity_ned_m_s, sp.acceleration_ned_m_s2
    for i in range(3):
        if not (_isfinite(p[i]) or _isfinite(v[i]) or _isfinite(a[i])):
            return False
    return all(_isfinite(k[0]) == _isfinite(k[1]) for k in (p, v, a))


def failsafe_setpoint() -> TrajectorySetpoint:
    """"Failsafe: stop and wait": zero velocity in all axes (the velocity estimate is always valid here)."""
    return TrajectorySetpoint(velocity_ned_m_s=(0.0, 0.0, 0.0))


def _add_if_not_nan(sp: float, add: float) -> float:
    """ControlMath::addIfNotNan."""
    if _isfinite(sp):
        return sp + add if _isfinite(add) else sp
    return add


def constrain_xy(v0x: float, v0y: float, v1x: float, v1y: float, vmax: float) -> tuple[float, float]:
    """ControlMath::constrainXY: limit |v0 + v1| to vmax, keeping as much of v0 as possible."""
    sx, sy = v0x + v1x, v0y + v1y
    if math.hypot(sx, sy) <= vmax:
        return sx, sy
    n0 = math.hypot(v0x, v0y)
    if n0 >= vmax:
        return (v0x / n0 * vmax, v0y / n0 * vmax) if n0 > 0.0 else (0.0, 0.0)
    if math.hypot(v1x - v0x, v1y - v0y) < 0.001:
        return v0x / n0 * vmax, v0y / n0 * vmax
    n1 = math.hypot(v1x, v1y)
    if n0 < 0.001:
        return v1x / n1 * vmax, v1y / n1 * vmax
    ux, uy = v1x / n1, v1y / n1
    m = ux * v0x + uy * v0y
    c = v0x * v0x + v0y * v0y - vmax * vmax
    s = -m + math.sqrt(m * m - c)
    return v0x + ux * s, v0y + uy * s


def limit_tilt(bz: Vec3, max_angle_rad: float) -> Vec3:
    """ControlMath::limitTilt against the world z axis (0, 0, 1)."""
    d = constrain(bz[2], -1.0, 1.0)
    angle = min(math.acos(d), max_angle_rad)
    rx, ry = bz[0], bz[1]
    rn = math.hypot(rx, ry)
    if rn * rn < 1.2e-7:  # FLT_EPSILON
        rx, ry, rn = 1.0, 0.0, 1.0
    s = math.sin(angle)
    return s * rx / rn, s * ry / rn, math.cos(angle)


def bodyz_to_attitude(bz: Vec3, yaw_rad: float) -> Vec4:
    """ControlMath::bodyzToAttitude: attitude with body z along bz (world frame) and the given heading."""
    if bz[0] * bz[0] + bz[1] * bz[1] + bz[2] * bz[2] < 1.2e-7:
        bz = (0.0, 0.0, 1.0)
    bz = normalized(bz)
    y_c = (-math.sin(yaw_rad), math.cos(yaw_rad), 0.0)
    bx = cross(y_c, bz)
    if bz[2] < 0.0:
        bx = (-bx[0], -bx[1], -bx[2])
    if abs(bz[2]) < 1e-6:
        bx = (0.0, 0.0, 1.0)
    bx = normalized(bx)
    return q_from_dcm_columns(bx, cross(bz, bx), bz)


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
        b = 2.0 * math.pi * cutoff_hz * dt_s
        a = b / (1.0 + b) if cutoff_hz > 0.0 else 1.0
        o, p = self._out, self._prev
        self._out = tuple(o[i] + a * ((vel[i] - p[i]) / dt_s - o[i]) for i in range(3))  # type: ignore[assignment]
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
        if input_valid(sp):
            self._last_valid, self._invalid_since_us = sp, None
            return sp, False
        if self._invalid_since_us is None:
            self._invalid_since_us = now_us
        if self._last_valid is not None and now_us - self._invalid_since_us < INVALID_HOLD_US:
            return self._last_valid, False
        return failsafe_setpoint(), True

    def update(self, pos: Vec3, vel: Vec3, yaw_rad: float, sp: TrajectorySetpoint, limits: PositionLimits,
               dt_s: float, now_us: int) -> PositionOutput:
        vel_dot = self._deriv.update(vel, dt_s, self.settings.veld_lp_hz)
        sp, in_failsafe = self.select_setpoint(sp, now_us)
        vel_sp = self._position_control(pos, sp, limits)
        acc_sp, thr = self._velocity_control(vel, vel_dot, vel_sp, sp.acceleration_ned_m_s2, limits, dt_s)
        yaw_sp = sp.yaw_rad if _isfinite(sp.yaw_rad) else yaw_rad
        yawspeed = sp.yawspeed_rad_s if _isfinite(sp.yawspeed_rad_s) else 0.0
        collective = math.sqrt(thr[0] * thr[0] + thr[1] * thr[1] + thr[2] * thr[2])
        q_sp = bodyz_to_attitude((-thr[0], -thr[1], -thr[2]), yaw_sp)
        local = TrajectorySetpoint(sp.position_ned_m, vel_sp, acc_sp, yaw_sp, yawspeed)
        return PositionOutput(thr, q_sp, collective, yaw_sp, yawspeed, local, in_failsafe)

    def _position_control(self, pos: Vec3, sp: TrajectorySetpoint, lim: PositionLimits) -> Vec3:
        kp = self.settings.pos_p
        psp, vff = sp.position_ned_m, sp.velocity_ned_m_s
        vpos = [(psp[i] - pos[i]) * kp[i] for i in range(3)]  # NaN where not controlled
        vsp = [_add_if_not_nan(vff[i], vpos[i]) for i in range(3)]
        vpos = [v if _isfinite(v) else 0.0 for v in vpos]
        vx, vy = constrain_xy(vpos[0], vpos[1], vsp[0] - vpos[0], vsp[1] - vpos[1], lim.vel_xy)
        return vx, vy, constrain(vsp[2], -lim.vel_up, lim.vel_dn)

    def _velocity_control(self, vel: Vec3, vel_dot: Vec3, vel_sp: Vec3, acc_ff: Vec3, lim: PositionLimits,
                          dt_s: float) -> tuple[Vec3, Vec3]:
        s = self.settings
        err = [vel_sp[i] - vel[i] for i in range(3)]
        acc = tuple(_add_if_not_nan(acc_ff[i], err[i] * s.vel_p[i] + self._vel_int[i] - vel_dot[i] * s.vel_d[i])
                    for i in range(3))
        thr = self._acceleration_control(acc, lim)  # type: ignore[arg-type]
        thr_min = max(lim.thr_min, 10e-4)
        if (thr[2] >= -thr_min and err[2] >= 0.0) or (thr[2] <= -lim.thr_max and err[2] <= 0.0):
            err[2] = 0.0  # vertical anti-windup
        thr = self._saturate_thrust(thr, lim.thr_max)
        # horizontal tracking anti-windup: feed back the part of the demand the thrust could not produce
        k = G / self.hover_thrust
        prod_x, prod_y = thr[0] * k, thr[1] * k
        if acc[0] * acc[0] + acc[1] * acc[1] > prod_x * prod_x + prod_y * prod_y:
            arw = 2.0 / s.vel_p[0]
            err[0] -= arw * (acc[0] - prod_x)
            err[1] -= arw * (acc[1] - prod_y)
        for i in range(3):
            if _isfinite(err[i]):
                self._vel_int[i] += err[i] * s.vel_i[i] * dt_s
        self._vel_int[2] = constrain(self._vel_int[2], -G, G)
        return acc, thr  # type: ignore[return-value]

    def _acceleration_control(self, acc: Vec3, lim: PositionLimits) -> Vec3:
        bz = limit_tilt(normalized((-acc[0], -acc[1], G)), lim.tilt_rad)
        h = self.hover_thrust
        collective = (acc[2] * (h / G) - h) / bz[2]
        collective = min(collective, -max(lim.thr_min, 10e-4))
        return bz[0] * collective, bz[1] * collective, bz[2] * collective

    def _saturate_thrust(self, thr: Vec3, thr_max: float) -> Vec3:
        """Prioritise vertical thrust but keep MPC_THR_XY_MARG for horizontal control."""
        xy = math.hypot(thr[0], thr[1])
        tmax2 = thr_max * thr_max
        allocated_xy = min(xy, self.settings.thr_xy_margin)
        tz = max(thr[2], -math.sqrt(max(tmax2 - allocated_xy * allocated_xy, 0.0)))
        xy_max = math.sqrt(max(tmax2 - tz * tz, 0.0))
        if xy > xy_max:
            return thr[0] / xy * xy_max, thr[1] / xy * xy_max, tz
        return thr[0], thr[1], tz


__all__ = ["NAN", "NAN3", "PositionControl", "PositionControlSettings", "PositionLimits", "PositionOutput"]
