"""Rigid-body quadrotor after PX4's SIH simulator (src/modules/simulation/simulator_sih/sih.cpp).

Flat-earth NED formulation of PX4@2024 (reference section 7.5 'V:'): forward Euler on velocity and angular rate,
trapezoidal position, exact quaternion exponential for the attitude. Forces and moments as sih.cpp
generate_force_and_torques (section 7.4): thrust linear in the motor command, quad-X moments, linear drag on the
air-relative velocity, linear angular damping. Motors lag with a first-order time constant SIH_T_TAU (read_motors).

Rotor order is PX4's for the 10040_sihsim_quadx airframe: r0 front-right, r1 rear-left, r2 front-left, r3 rear-right;
r0/r1 spin so that a higher command yaws the nose right (positive Mz).

Ground: z = 0 (the home altitude). While on the ground with the net vertical force pointing down the vehicle sits
still: no velocity, no rates, level attitude with its yaw kept. It leaves the ground as soon as thrust exceeds
weight. A touchdown stops it in one step (no bounce), like SIH's ground handling.

Vectors are tuples of plain floats (ARCHITECTURE.md, On the tick path).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from math import cos, sin, sqrt
from typing import Final

from sitl_emu.control.qmath import (
    add,
    constrain,
    dcm_z,
    norm,
    q_from_yaw,
    q_mul,
    rotate_world_to_body,
    scale,
    sub,
    yaw_from_q,
)
from sitl_emu.types import Vec3, Vec4

GRAVITY_M_S2: Final = 9.80665  # PX4 CONSTANTS_ONE_G
DEFAULT_DT_S: Final = 0.004  # SIH lockstep at 250 Hz (reference 7.6)
MAX_RATE_RAD_S: Final = 6.0 * math.pi  # sih.cpp clamps the body rates to +-6 pi rad/s


@dataclass(slots=True)
class RigidBodyState:
    """Truth state of the vehicle. Local NED position relative to the home point, FRD body rates."""

    pos_ned_m: Vec3 = (0.0, 0.0, 0.0)
    vel_ned_m_s: Vec3 = (0.0, 0.0, 0.0)
    q_wxyz: Vec4 = (1.0, 0.0, 0.0, 0.0)
    rates_frd_rad_s: Vec3 = (0.0, 0.0, 0.0)
    motors: Vec4 = (0.0, 0.0, 0.0, 0.0)  # 0..1, after the motor lag
    acc_ned_m_s2: Vec3 = (0.0, 0.0, 0.0)  # last kinematic acceleration
    specific_force_frd: Vec3 = (0.0, 0.0, -GRAVITY_M_S2)  # what an accelerometer reads
    on_ground: bool = True

    # written out, the same as the generated one (ARCHITECTURE.md, On the tick path)
    def __init__(self, pos_ned_m: Vec3 = (0.0, 0.0, 0.0), vel_ned_m_s: Vec3 = (0.0, 0.0, 0.0),
                 q_wxyz: Vec4 = (1.0, 0.0, 0.0, 0.0), rates_frd_rad_s: Vec3 = (0.0, 0.0, 0.0),
                 motors: Vec4 = (0.0, 0.0, 0.0, 0.0), acc_ned_m_s2: Vec3 = (0.0, 0.0, 0.0),
                 specific_force_frd: Vec3 = (0.0, 0.0, -GRAVITY_M_S2), on_ground: bool = True) -> None:
        self.pos_ned_m = pos_ned_m
        self.vel_ned_m_s = vel_ned_m_s
        self.q_wxyz = q_wxyz
        self.rates_frd_rad_s = rates_frd_rad_s
        self.motors = motors
        self.acc_ned_m_s2 = acc_ned_m_s2
        self.specific_force_frd = specific_force_frd
        self.on_ground = on_ground


# RigidBodyState's field names, for copying a state (a compiled class has no __slots__: ARCHITECTURE.md)
RIGID_BODY_FIELDS = ("pos_ned_m", "vel_ned_m_s", "q_wxyz", "rates_frd_rad_s", "motors", "acc_ned_m_s2",
                     "specific_force_frd", "on_ground")


@dataclass(frozen=True, slots=True)
class SihConfig:
    mass_kg: float = 1.0
    ixx: float = 0.025
    iyy: float = 0.025
    izz: float = 0.030
    t_max_n: float = 5.0
    q_max_nm: float = 0.1
    l_roll_m: float = 0.2
    l_pitch_m: float = 0.2
    kdv: float = 1.0
    kdw: float = 0.025
    t_tau_s: float = 0.05
    # SIH_WIND_N/E: wind FROM the north/east (sih_params.yaml); sih.cpp ecefToNed adds them to the ground velocity to
    # get the apparent air velocity, so the air moves towards (-wind_n, -wind_e)
    wind_n_m_s: float = 0.0
    wind_e_m_s: float = 0.0

    @property
    def hover_command(self) -> float:
        """Motor command (all four equal) that balances weight: m g / (4 T_MAX)."""
        return self.mass_kg * GRAVITY_M_S2 / (4.0 * self.t_max_n)


def step(state: RigidBodyState, motor_cmd: Vec4, dt_s: float, cfg: SihConfig,
         wind_ned_m_s: Vec3 | None = None) -> RigidBodyState:
    """Advance the state by dt_s under the given motor commands (0..1 each); the input state is not changed.

    `wind_ned_m_s` is the air mass velocity (sitl_emu/disturbance/wind.py); None: cfg's constant SIH wind."""
    u = _motor_lag(state.motors, motor_cmd, dt_s, cfg.t_tau_s)
    thrust_n = cfg.t_max_n * (u[0] + u[1] + u[2] + u[3])  # along body -z
    wind = (-cfg.wind_n_m_s, -cfg.wind_e_m_s, 0.0) if wind_ned_m_s is None else wind_ned_m_s
    acc = _acceleration_ned(state.q_wxyz, state.vel_ned_m_s, thrust_n, cfg, wind)
    pos, vel = state.pos_ned_m, state.vel_ned_m_s
    if state.on_ground and acc[2] >= 0.0:
        return _grounded(state, u, (pos[0], pos[1], 0.0))
    # forward Euler on the velocity, trapezoidal position
    new_vel = add(vel, scale(acc, dt_s))
    mean_vel = scale(add(vel, new_vel), 0.5)
    new_pos = add(pos, scale(mean_vel, dt_s))
    if new_pos[2] >= 0.0:  # touchdown: stop in one step, never sink, never bounce
        return _grounded(state, u, (new_pos[0], new_pos[1], 0.0))
    specific_force = rotate_world_to_body(state.q_wxyz, (acc[0], acc[1], acc[2] - GRAVITY_M_S2))  # accelerometer
    return RigidBodyState(new_pos, new_vel, _attitude_step(state.q_wxyz, state.rates_frd_rad_s, dt_s),
                          _rates_step(state.rates_frd_rad_s, u, dt_s, cfg), u, acc, specific_force, False)


def _motor_lag(motors: Vec4, cmd: Vec4, dt_s: float, tau_s: float) -> Vec4:
    """sih.cpp read_motors: u += dt / tau (u_sp - u) for each motor, the commands clamped to 0..1 (NaN -> 0)."""
    k = 1.0 if tau_s <= dt_s else dt_s / tau_s
    c0, c1, c2, c3 = cmd
    c0 = 0.0 if not c0 >= 0.0 else (1.0 if c0 > 1.0 else c0)  # `not c >= 0` also catches NaN
    c1 = 0.0 if not c1 >= 0.0 else (1.0 if c1 > 1.0 else c1)
    c2 = 0.0 if not c2 >= 0.0 else (1.0 if c2 > 1.0 else c2)
    c3 = 0.0 if not c3 >= 0.0 else (1.0 if c3 > 1.0 else c3)
    m0, m1, m2, m3 = motors
    return m0 + k * (c0 - m0), m1 + k * (c1 - m1), m2 + k * (c2 - m2), m3 + k * (c3 - m3)


def _acceleration_ned(q: Vec4, vel: Vec3, thrust_n: float, cfg: SihConfig, wind: Vec3) -> Vec3:
    """sih.cpp generate_force_and_torques: thrust along body -z, linear drag on the air-relative velocity, gravity."""
    m = cfg.mass_kg
    f_x, f_y, f_z = sub(scale(dcm_z(q), -thrust_n), scale(sub(vel, wind), cfg.kdv))  # thrust and drag, N
    return f_x / m, f_y / m, (f_z + m * GRAVITY_M_S2) / m


def _rates_step(rates: Vec3, u: Vec4, dt_s: float, cfg: SihConfig) -> Vec3:
    """Quad-X moments with angular damping, the gyroscopic term, diagonal inertia; rates clamped to +-6 pi rad/s."""
    p, q, r = rates
    m_x = cfg.l_roll_m * cfg.t_max_n * (-u[0] + u[1] + u[2] - u[3]) - cfg.kdw * p
    m_y = cfg.l_pitch_m * cfg.t_max_n * (u[0] - u[1] + u[2] - u[3]) - cfg.kdw * q
    m_z = cfg.q_max_nm * (u[0] + u[1] - u[2] - u[3]) - cfg.kdw * r
    ixx, iyy, izz = cfg.ixx, cfg.iyy, cfg.izz
    dp = (m_x + (iyy - izz) * q * r) / ixx
    dq = (m_y + (izz - ixx) * r * p) / iyy
    dr = (m_z + (ixx - iyy) * p * q) / izz
    p, q, r = add(rates, scale((dp, dq, dr), dt_s))
    lim = MAX_RATE_RAD_S  # per axis, as a scalar: a module tuple of limits would be looked up in the module's dict
    return constrain(p, -lim, lim), constrain(q, -lim, lim), constrain(r, -lim, lim)


def _attitude_step(q: Vec4, rates: Vec3, dt_s: float) -> Vec4:
    """q <- q (x) exp(omega dt / 2), with the rates at the start of the step, normalised.

    Normalised by multiplying with 1 / |q|, not with qmath.q_normalized (which divides by |q|): the last bit differs
    and the golden flights (tools/golden_flights.py) keep SIH's arithmetic as it was recorded."""
    w_x, w_y, w_z = rates
    n = norm(rates)  # |omega|
    if n < 1e-12:
        return q
    half = 0.5 * n * dt_s
    k = sin(half) / n
    qw, qx, qy, qz = q_mul(q, (cos(half), w_x * k, w_y * k, w_z * k))
    inv = 1.0 / sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
    return qw * inv, qx * inv, qy * inv, qz * inv


def _grounded(state: RigidBodyState, u: Vec4, pos: Vec3) -> RigidBodyState:
    """Resting on the ground: still, level (yaw kept), the accelerometer reads the ground's reaction."""
    q = state.q_wxyz
    if not (state.on_ground and q[1] == 0.0 == q[2]):
        q = q_from_yaw(yaw_from_q(q))
    return RigidBodyState(pos, (0.0, 0.0, 0.0), q, (0.0, 0.0, 0.0), u, (0.0, 0.0, 0.0),
                          (0.0, 0.0, -GRAVITY_M_S2), True)
