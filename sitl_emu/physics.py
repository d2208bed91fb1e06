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

Plain floats are used throughout: for 3-vectors they are several times faster than numpy in CPython.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from math import cos, sin, sqrt
from typing import Final

from sitl_emu.params import ParamRegistry
from sitl_emu.types import Vec3, Vec4

GRAVITY_M_S2: Final = 9.80665  # PX4 CONSTANTS_ONE_G
DEFAULT_DT_S: Final = 0.004  # SIH lockstep at 250 Hz (reference 7.6)
MAX_RATE_RAD_S: Final = 6.0 * math.pi  # sih.cpp clamps the body rates to +-6 pi rad/s
_MIN_RATE: Final = -MAX_RATE_RAD_S


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

    # Written out (the same as the one @dataclass would generate), so that `make speedups` compiles it: mypyc leaves
    # a generated __init__ to the dataclasses module, i.e. interpreted, and a state is built on every physics step.
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


# RigidBodyState's field names, for copying a state: a class compiled by `make speedups` (mypyc) has no __slots__.
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
    wind_n_m_s: float = 0.0
    wind_e_m_s: float = 0.0

    @classmethod
    def from_params(cls, registry: ParamRegistry) -> SihConfig:
        g = registry.get
        return cls(
            mass_kg=g("SIH_MASS"), ixx=g("SIH_IXX"), iyy=g("SIH_IYY"), izz=g("SIH_IZZ"),
            t_max_n=g("SIH_T_MAX"), q_max_nm=g("SIH_Q_MAX"), l_roll_m=g("SIH_L_ROLL"), l_pitch_m=g("SIH_L_PITCH"),
            kdv=g("SIH_KDV"), kdw=g("SIH_KDW"), t_tau_s=g("SIH_T_TAU"),
            wind_n_m_s=g("SIH_WIND_N"), wind_e_m_s=g("SIH_WIND_E"),
        )

    @property
    def hover_command(self) -> float:
        """Motor command (all four equal) that balances weight: m g / (4 T_MAX)."""
        return self.mass_kg * GRAVITY_M_S2 / (4.0 * self.t_max_n)


def _level_q(q: Vec4) -> Vec4:
    """The attitude with roll and pitch removed, yaw kept."""
    w, x, y, z = q
    yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return math.cos(yaw / 2.0), 0.0, 0.0, math.sin(yaw / 2.0)


def step(state: RigidBodyState, motor_cmd: Sequence[float], dt_s: float, cfg: SihConfig) -> RigidBodyState:
    """Advance the state by dt_s under the given motor commands (0..1 each); the input state is not changed.

    Runs every tick: the motor lag (sih.cpp read_motors: u += dt/tau (u_sp - u), commands clamped to 0..1, NaN -> 0),
    the rate clamp (+-6 pi rad/s), the accelerometer rotation R^T v and the quaternion exponential are inlined here.
    """
    tau = cfg.t_tau_s
    k = 1.0 if tau <= dt_s else dt_s / tau
    c0, c1, c2, c3 = motor_cmd
    c0 = 0.0 if not c0 >= 0.0 else (1.0 if c0 > 1.0 else c0)  # `not c >= 0` also catches NaN
    c1 = 0.0 if not c1 >= 0.0 else (1.0 if c1 > 1.0 else c1)
    c2 = 0.0 if not c2 >= 0.0 else (1.0 if c2 > 1.0 else c2)
    c3 = 0.0 if not c3 >= 0.0 else (1.0 if c3 > 1.0 else c3)
    m0, m1, m2, m3 = state.motors
    u0, u1, u2, u3 = m0 + k * (c0 - m0), m1 + k * (c1 - m1), m2 + k * (c2 - m2), m3 + k * (c3 - m3)
    u = (u0, u1, u2, u3)
    t_max = cfg.t_max_n
    thrust_n = t_max * (u0 + u1 + u2 + u3)  # along body -z
    q_wxyz = state.q_wxyz
    w, x, y, z = q_wxyz
    # third column of R (body z axis in NED), times -thrust
    bzx, bzy, bzz = 2.0 * (x * z + w * y), 2.0 * (y * z - w * x), 1.0 - 2.0 * (x * x + y * y)
    vn, ve, vd = state.vel_ned_m_s
    m, kdv = cfg.mass_kg, cfg.kdv
    fn = -thrust_n * bzx - kdv * (vn - cfg.wind_n_m_s)
    fe = -thrust_n * bzy - kdv * (ve - cfg.wind_e_m_s)
    fd = -thrust_n * bzz - kdv * vd + m * GRAVITY_M_S2
    an, ae, ad = fn / m, fe / m, fd / m
    pn, pe, pd = state.pos_ned_m
    if state.on_ground and ad >= 0.0:
        return _grounded(state, u, (pn, pe, 0.0), thrust_n, cfg)
    # moments (sih.cpp generate_force_and_torques), damping, gyroscopic term, diagonal inertia
    p, q, r = state.rates_frd_rad_s
    kdw = cfg.kdw
    mx = cfg.l_roll_m * t_max * (-u0 + u1 + u2 - u3) - kdw * p
    my = cfg.l_pitch_m * t_max * (u0 - u1 + u2 - u3) - kdw * q
    mz = cfg.q_max_nm * (u0 + u1 - u2 - u3) - kdw * r
    ixx, iyy, izz = cfg.ixx, cfg.iyy, cfg.izz
    dp = (mx + (iyy - izz) * q * r) / ixx
    dq = (my + (izz - ixx) * r * p) / iyy
    dr = (mz + (ixx - iyy) * p * q) / izz
    np_, nq, nr = p + dp * dt_s, q + dq * dt_s, r + dr * dt_s
    np_ = MAX_RATE_RAD_S if np_ > MAX_RATE_RAD_S else (_MIN_RATE if np_ < _MIN_RATE else np_)
    nq = MAX_RATE_RAD_S if nq > MAX_RATE_RAD_S else (_MIN_RATE if nq < _MIN_RATE else nq)
    nr = MAX_RATE_RAD_S if nr > MAX_RATE_RAD_S else (_MIN_RATE if nr < _MIN_RATE else nr)
    nvn, nve, nvd = vn + an * dt_s, ve + ae * dt_s, vd + ad * dt_s
    npd = pd + 0.5 * (vd + nvd) * dt_s
    pos = (pn + 0.5 * (vn + nvn) * dt_s, pe + 0.5 * (ve + nve) * dt_s, npd)
    if npd >= 0.0:  # touchdown: stop in one step, never sink, never bounce
        return _grounded(state, u, (pos[0], pos[1], 0.0), thrust_n, cfg)
    # accelerometer: R^T (a - g) in FRD; R's third column is (bzx, bzy, bzz) above
    fz = ad - GRAVITY_M_S2
    r00, r01 = 1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z)
    r10, r11 = 2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z)
    r20, r21 = 2.0 * (x * z - w * y), 2.0 * (y * z + w * x)
    sf = (r00 * an + r10 * ae + r20 * fz, r01 * an + r11 * ae + r21 * fz, bzx * an + bzy * ae + bzz * fz)
    # attitude: q <- q (x) exp(omega dt / 2) with the rates at the start of the step, normalised
    n = sqrt(p * p + q * q + r * r)
    if n < 1e-12:
        q_new = q_wxyz
    else:
        half = 0.5 * n * dt_s
        dw, k = cos(half), sin(half) / n
        dx, dy, dz = p * k, q * k, r * k
        qw = w * dw - x * dx - y * dy - z * dz
        qx = w * dx + x * dw + y * dz - z * dy
        qy = w * dy - x * dz + y * dw + z * dx
        qz = w * dz + x * dy - y * dx + z * dw
        inv = 1.0 / sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
        q_new = (qw * inv, qx * inv, qy * inv, qz * inv)
    return RigidBodyState(pos, (nvn, nve, nvd), q_new, (np_, nq, nr), u, (an, ae, ad), sf, False)


def _grounded(state: RigidBodyState, u: Vec4, pos: Vec3, thrust_n: float, cfg: SihConfig) -> RigidBodyState:
    """Resting on the ground: still, level, the accelerometer reads the ground's reaction."""
    q = state.q_wxyz if state.on_ground and state.q_wxyz[1] == 0.0 == state.q_wxyz[2] else _level_q(state.q_wxyz)
    return RigidBodyState(pos, (0.0, 0.0, 0.0), q, (0.0, 0.0, 0.0), u, (0.0, 0.0, 0.0),
                          (0.0, 0.0, -GRAVITY_M_S2), True)


def hover_state(altitude_m: float, cfg: SihConfig | None = None, yaw_rad: float = 0.0) -> RigidBodyState:
    """A vehicle hovering at `altitude_m` above the ground, motors at the hover command (for tests and tools)."""
    cfg = cfg or SihConfig()
    h = cfg.hover_command
    q = (math.cos(yaw_rad / 2.0), 0.0, 0.0, math.sin(yaw_rad / 2.0))
    return RigidBodyState(pos_ned_m=(0.0, 0.0, -altitude_m), q_wxyz=q, motors=(h, h, h, h), on_ground=False)
