"""Multicopter position controller after PX4's PositionControl (src/modules/mc_pos_control/PositionControl/
PositionControl.cpp).

Position P -> velocity PID -> acceleration -> thrust vector -> attitude setpoint, with PX4's rules:
- validity (PositionControl.cpp _inputValid): every axis needs a position, velocity or acceleration setpoint, and x/y
  come in pairs for each kind. What to fly instead of an invalid setpoint is the wrapper's choice (cascade.py, as
  MulticopterPositionControl's): `update` is given a valid one;
- the horizontal velocity limit keeps the position term first (ControlMath::constrainXY);
- vertical anti-windup on thrust saturation, horizontal tracking anti-windup (Rundqwist), vertical integral <= g;
- tilt limit (ControlMath::limitTilt), minimum thrust, and the horizontal margin MPC_THR_XY_MARG.
The velocity derivative for the D term is MulticopterPositionControl's BlockDerivative (low-pass MPC_VELD_LP).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from math import sqrt
from typing import Final

from sitl_emu.control.control_math import add_if_not_nan3, bodyz_to_attitude, constrain_xy, limit_tilt
from sitl_emu.control.filters import LowPassDerivative
from sitl_emu.control.qmath import (
    at_least,
    at_most,
    constrain,
    emult,
    hypot,
    isfinite,
    norm,
    normalized,
    scale,
    sub,
)
from sitl_emu.types import TrajectorySetpoint, Vec3, Vec4

G: Final = 9.80665  # CONSTANTS_ONE_G
THR_MIN_FLOOR: Final = 10e-4  # PositionControl::setThrustLimits: enough thrust to infer an attitude from


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


@dataclass(slots=True)
class PositionOutput:
    """One position-control cycle's result (see ARCHITECTURE.md, On the tick path)."""

    thrust_ned: Vec3  # normalised thrust vector (z < 0 is up)
    q_sp: Vec4
    collective: float  # |thrust|, 0..1
    yaw_sp_rad: float
    yawspeed_sp_rad_s: float
    position_sp_ned_m: Vec3  # the position setpoint used
    velocity_sp_ned_m_s: Vec3  # incl. the P-correction
    acceleration_sp_ned_m_s2: Vec3

    def __init__(self, thrust_ned: Vec3, q_sp: Vec4, collective: float, yaw_sp_rad: float, yawspeed_sp_rad_s: float,
                 position_sp_ned_m: Vec3, velocity_sp_ned_m_s: Vec3, acceleration_sp_ned_m_s2: Vec3) -> None:
        self.thrust_ned = thrust_ned
        self.q_sp = q_sp
        self.collective = collective
        self.yaw_sp_rad = yaw_sp_rad
        self.yawspeed_sp_rad_s = yawspeed_sp_rad_s
        self.position_sp_ned_m = position_sp_ned_m
        self.velocity_sp_ned_m_s = velocity_sp_ned_m_s
        self.acceleration_sp_ned_m_s2 = acceleration_sp_ned_m_s2

    @property
    def local_setpoint(self) -> TrajectorySetpoint:
        """What the controller used, incl. P-corrections (POSITION_TARGET_LOCAL_NED); built on demand."""
        return TrajectorySetpoint(self.position_sp_ned_m, self.velocity_sp_ned_m_s, self.acceleration_sp_ned_m_s2,
                                  self.yaw_sp_rad, self.yawspeed_sp_rad_s)


def input_valid(sp: TrajectorySetpoint) -> bool:
    """PositionControl::_inputValid (the estimate is always valid here)."""
    pos, vel, acc = sp.position_ned_m, sp.velocity_ned_m_s, sp.acceleration_ned_m_s2
    pos_x, vel_x, acc_x = isfinite(pos[0]), isfinite(vel[0]), isfinite(acc[0])
    in_pairs = pos_x == isfinite(pos[1]) and vel_x == isfinite(vel[1]) and acc_x == isfinite(acc[1])
    # every axis needs some setpoint (with x and y in pairs, x stands for both)
    return in_pairs and (pos_x or vel_x or acc_x) and (isfinite(pos[2]) or isfinite(vel[2]) or isfinite(acc[2]))


class PositionControl:
    """One instance per vehicle; `update` is pure apart from the integrator and the filter.

    As in PX4, the wrapper (cascade.py, MulticopterPositionControl's role) sets the limits before every update and
    chooses the setpoint it flies (a valid one: input_valid)."""

    def __init__(self, settings: PositionControlSettings | None = None) -> None:
        self._deriv = LowPassDerivative(0.0)
        self.settings = settings or PositionControlSettings()
        s = self.settings
        self.hover_thrust = s.thr_hover
        self.set_velocity_limits(s.vel_max_xy, s.vel_max_up, s.vel_max_dn)
        self.set_thrust_limits(s.thr_min, s.thr_max)
        self.set_tilt_limit(s.tilt_max_air_rad)
        self._vel_int: Vec3 = (0.0, 0.0, 0.0)

    @property
    def settings(self) -> PositionControlSettings:
        return self._settings

    @settings.setter
    def settings(self, s: PositionControlSettings) -> None:
        self._settings = s
        self._deriv.cutoff_hz = s.veld_lp_hz

    def set_velocity_limits(self, horizontal: float, up: float, down: float) -> None:
        """m/s; `up` may be negative at the start of the takeoff ramp (it then still pushes down)."""
        self._lim_vel_xy, self._lim_vel_up, self._lim_vel_dn = horizontal, up, down

    def set_thrust_limits(self, minimum: float, maximum: float) -> None:
        self._lim_thr_min = minimum if minimum > THR_MIN_FLOOR else THR_MIN_FLOOR
        self._lim_thr_max = maximum

    def set_tilt_limit(self, tilt_rad: float) -> None:
        self._lim_tilt = tilt_rad

    def reset(self) -> None:
        self.reset_integral()
        self._deriv.reset()

    def reset_integral(self) -> None:
        self._vel_int = (0.0, 0.0, 0.0)

    def set_hover_thrust(self, hover: float) -> None:
        self.hover_thrust = hover

    def update_hover_thrust(self, hover_new: float, acc_sp_z: float) -> None:
        """PositionControl::updateHoverThrust: change the hover thrust without a thrust step (integrator absorbs)."""
        if hover_new > 1.2e-7:
            i0, i1, i2 = self._vel_int
            self._vel_int = (i0, i1, i2 + ((acc_sp_z - G) * self.hover_thrust / hover_new + G - acc_sp_z))
            self.hover_thrust = hover_new

    def update(self, pos: Vec3, vel: Vec3, yaw_rad: float, sp: TrajectorySetpoint, dt_s: float) -> PositionOutput:
        """One cycle (PositionControl::update and getAttitudeSetpoint) for a valid setpoint `sp` (input_valid)."""
        vel_dot = self._deriv.update(vel, dt_s)
        vel_sp = self._position_control(pos, sp)
        acc_sp, thrust_sp = self._velocity_control(vel, vel_dot, vel_sp, sp.acceleration_ned_m_s2, dt_s)
        yaw_sp = sp.yaw_rad if isfinite(sp.yaw_rad) else yaw_rad  # no yaw setpoint: keep the heading
        yawspeed_sp = sp.yawspeed_rad_s if isfinite(sp.yawspeed_rad_s) else 0.0
        q_sp = bodyz_to_attitude(scale(thrust_sp, -1.0), yaw_sp)  # ControlMath::thrustToAttitude
        return PositionOutput(thrust_sp, q_sp, norm(thrust_sp), yaw_sp, yawspeed_sp, sp.position_ned_m, vel_sp, acc_sp)

    def _position_control(self, pos: Vec3, sp: TrajectorySetpoint) -> Vec3:
        """PositionControl::_positionControl: P on the position error plus the velocity feed-forward, limited."""
        vel_sp_position = emult(sub(sp.position_ned_m, pos), self._settings.pos_p)  # NaN where not controlled
        vel_sp = add_if_not_nan3(sp.velocity_ned_m_s, vel_sp_position)
        p_x, p_y = vel_sp_position[0], vel_sp_position[1]
        p_xy = (p_x if isfinite(p_x) else 0.0, p_y if isfinite(p_y) else 0.0)  # setZeroIfNan
        ff_xy = (vel_sp[0] - p_xy[0], vel_sp[1] - p_xy[1])
        vel_sp_x, vel_sp_y = constrain_xy(p_xy, ff_xy, self._lim_vel_xy)  # the position term first
        return vel_sp_x, vel_sp_y, constrain(vel_sp[2], -self._lim_vel_up, self._lim_vel_dn)

    def _velocity_control(self, vel: Vec3, vel_dot: Vec3, vel_sp: Vec3, acc_ff: Vec3,
                          dt_s: float) -> tuple[Vec3, Vec3]:
        """PositionControl::_velocityControl: velocity PID -> acceleration -> thrust, with the anti-windups.

        Returns the acceleration setpoint and the thrust setpoint."""
        s = self._settings
        e = sub(vel_sp, vel)  # the velocity error
        kp, i, kd = s.vel_p, self._vel_int, s.vel_d
        acc_sp_velocity = (e[0] * kp[0] + i[0] - vel_dot[0] * kd[0], e[1] * kp[1] + i[1] - vel_dot[1] * kd[1],
                           e[2] * kp[2] + i[2] - vel_dot[2] * kd[2])  # PID: P e + I - D d(vel)/dt
        acc_sp = add_if_not_nan3(acc_ff, acc_sp_velocity)
        thrust_sp = self._acceleration_control(acc_sp)
        err_x, err_y, err_z = e
        # vertical anti-windup: no integration into a saturated vertical thrust
        if ((thrust_sp[2] >= -self._lim_thr_min and err_z >= 0.0)
                or (thrust_sp[2] <= -self._lim_thr_max and err_z <= 0.0)):
            err_z = 0.0
        thrust_sp = self._saturate_thrust(thrust_sp)
        # horizontal tracking anti-windup (Rundqwist): feed back the acceleration the thrust could not produce
        k = G / self.hover_thrust
        produced_x, produced_y = thrust_sp[0] * k, thrust_sp[1] * k
        if acc_sp[0] * acc_sp[0] + acc_sp[1] * acc_sp[1] > produced_x * produced_x + produced_y * produced_y:
            arw_gain = 2.0 / s.vel_p[0]
            err_x -= arw_gain * (acc_sp[0] - produced_x)
            err_y -= arw_gain * (acc_sp[1] - produced_y)
        i_x, i_y, i_z = self._vel_int
        self._vel_int = (_integrate(i_x, err_x, s.vel_i[0], dt_s), _integrate(i_y, err_y, s.vel_i[1], dt_s),
                         constrain(_integrate(i_z, err_z, s.vel_i[2], dt_s), -G, G))
        return acc_sp, thrust_sp

    def _acceleration_control(self, acc_sp: Vec3) -> Vec3:
        """PositionControl::_accelerationControl: the thrust vector for acc_sp, hover thrust balancing gravity."""
        body_z = limit_tilt(normalized((-acc_sp[0], -acc_sp[1], G)), self._lim_tilt)
        hover = self.hover_thrust
        thrust_ned_z = acc_sp[2] * (hover / G) - hover
        collective = thrust_ned_z / body_z[2]  # projected onto the body z axis
        collective = at_most(collective, -self._lim_thr_min)  # at least the minimum thrust (NED: upwards < 0)
        return scale(body_z, collective)

    def _saturate_thrust(self, thrust_sp: Vec3) -> Vec3:
        """Prioritise vertical thrust, keeping MPC_THR_XY_MARG of it for horizontal control."""
        t_x, t_y, t_z = thrust_sp
        xy = hypot(t_x, t_y)
        thr_max_sq = self._lim_thr_max * self._lim_thr_max
        margin = self._settings.thr_xy_margin
        allocated_xy = at_most(xy, margin)  # the horizontal thrust kept, at most the margin
        t_z_max_sq = thr_max_sq - allocated_xy * allocated_xy
        t_z_lim = -sqrt(t_z_max_sq if t_z_max_sq > 0.0 else 0.0)
        t_z = at_least(t_z, t_z_lim)  # the vertical thrust left beside it
        xy_max_sq = thr_max_sq - t_z * t_z
        xy_max = sqrt(xy_max_sq if xy_max_sq > 0.0 else 0.0)  # the horizontal thrust left
        if xy > xy_max:
            t_x, t_y = t_x / xy * xy_max, t_y / xy * xy_max
        return t_x, t_y, t_z


def _integrate(integral: float, error: float, gain: float, dt_s: float) -> float:
    """One integrator step; a NaN error (an axis not controlled) leaves the integral as it is."""
    return integral + error * gain * dt_s if isfinite(error) else integral


__all__ = ["PositionControl", "PositionControlSettings", "PositionOutput"]
