"""The multicopter control cascade the vehicle calls every physics tick.

trajectory setpoint -> PositionControl (with TakeoffHandling, as MulticopterPositionControl.cpp wraps it)
-> attitude setpoint -> AttitudeControl -> rate setpoint -> RateControl -> torque -> quad-X mixer -> motors 0..1.
An offboard attitude/rate setpoint (SET_ATTITUDE_TARGET) bypasses position control (PX4 then skips the takeoff
ramp: updateTakeoffState(..., skip_takeoff=true)). The estimate is the true state.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from math import isfinite
from typing import Final

from sitl_emu.control.attitude import AttitudeControl, AttitudeControlSettings
from sitl_emu.control.hover import HoverThrustEstimator, HoverThrustSettings
from sitl_emu.control.mixer import mix
from sitl_emu.control.position import (
    PositionControl,
    PositionControlSettings,
    PositionOutput,
)
from sitl_emu.control.qmath import q_normalized, yaw_from_q
from sitl_emu.control.rate import RateControl, RateControlSettings
from sitl_emu.control.takeoff import TakeoffHandling, TakeoffState
from sitl_emu.params import ParamRegistry
from sitl_emu.physics import RigidBodyState
from sitl_emu.types import NAN, AttitudeSetpoint, TrajectorySetpoint, Vec3, Vec4

IDLE_SETPOINT: Final = TrajectorySetpoint(acceleration_ned_m_s2=(0.0, 0.0, 100.0))  # "no thrust" (not yet taken off)
TILT_SLEW_RAD_S: Final = 0.2  # MulticopterPositionControl _tilt_limit_slew_rate
ZERO4: Vec4 = (0.0, 0.0, 0.0, 0.0)
# mc_pos_control runs on each vehicle_local_position update: EKF2 at 100 Hz (EKF2_PREDICT_US 10 ms) in PX4 SITL.
# Here every 8 ms (every second 250 Hz physics tick); attitude and rate control run every tick.
POSITION_PERIOD_US: Final = 8000
_FLIGHT: Final = TakeoffState.FLIGHT
_RAMPUP: Final = TakeoffState.RAMPUP
# takeoff_state's names, made once: it is read on every tick, and an enum's .name is a Python-level property
_TAKEOFF_NAMES: Final = {state: state.name.lower() for state in TakeoffState}


@dataclass(frozen=True, slots=True)
class CascadeSettings:
    position: PositionControlSettings
    attitude: AttitudeControlSettings
    rate: RateControlSettings
    spoolup_time_s: float = 1.0
    tko_ramp_t_s: float = 3.0

    @classmethod
    def from_params(cls, reg: ParamRegistry) -> CascadeSettings:
        spool = reg.get("COM_SPOOLUP_TIME") if "COM_SPOOLUP_TIME" in reg else 1.0
        return cls(PositionControlSettings.from_params(reg), AttitudeControlSettings.from_params(reg),
                   RateControlSettings.from_params(reg), spool, reg.get("MPC_TKO_RAMP_T"))


class MulticopterControl:
    """Position/attitude/rate cascade plus mixer, rebuilt from the registry whenever `registry.version` changes."""

    def __init__(self, registry: ParamRegistry) -> None:
        self._registry = registry
        self._version = -1
        self._sat_pos: tuple[bool, bool, bool] = (False, False, False)
        self._sat_neg: tuple[bool, bool, bool] = (False, False, False)
        self._local_setpoint: TrajectorySetpoint | None = None
        self._local_out: PositionOutput | None = None
        self.position = PositionControl()
        self.attitude = AttitudeControl()
        self.rate = RateControl()
        self.takeoff = TakeoffHandling()
        self.hte = HoverThrustEstimator()
        self._refresh()
        self.reset()

    # --- telemetry -------------------------------------------------------------------------------------------
    @property
    def local_setpoint(self) -> TrajectorySetpoint | None:
        ls = self._local_setpoint
        if ls is None and self._local_out is not None:  # built on first read after a position-control cycle
            ls = self._local_setpoint = self._local_out.local_setpoint
        return ls

    @property
    def attitude_setpoint_q_wxyz(self) -> Vec4 | None:
        return self._q_sp

    @property
    def rates_setpoint_rad_s(self) -> Vec3:
        return self._rates_sp

    @property
    def thrust_setpoint(self) -> float:
        return self._thrust

    @property
    def hover_thrust(self) -> float:
        return self.position.hover_thrust

    @property
    def takeoff_state(self) -> str:
        return _TAKEOFF_NAMES[self.takeoff.state]

    @property
    def tilt_limit_rad(self) -> float:
        return self._tilt_limit

    @property
    def in_failsafe(self) -> bool:
        return self._in_failsafe

    # --- control -----------------------------------------------------------------------------------------------
    def reset(self, flying: bool = False) -> None:
        """Forget integrators and filters; `flying=True` starts in the FLIGHT takeoff state (vehicle already up)."""
        s = self.settings.position
        self.position.reset()
        self.position.set_hover_thrust(s.thr_hover)
        self.hte.reset()
        self._hte_in_air = False
        self.rate.reset()
        self._local_setpoint = None
        self._local_out = None  # the local setpoint's source, until it is built
        self._q_sp: Vec4 | None = None
        self._rates_sp: Vec3 = (0.0, 0.0, 0.0)
        self._thrust = 0.0
        self._in_failsafe = False
        self._pos_out: PositionOutput | None = None
        self._pos_last_us = 0
        self._tilt_limit = s.tilt_max_air_rad if flying else s.tilt_max_lnd_rad
        self._flying_reset = flying
        self.takeoff.state = TakeoffState.FLIGHT if flying else TakeoffState.DISARMED

    def update(self, state: RigidBodyState, setpoint: TrajectorySetpoint | None, attitude_sp: AttitudeSetpoint | None,
               armed: bool, landed: bool, now_us: int, dt_s: float, *, ground_contact: bool = False,
               speed_up_m_s: float = NAN, speed_down_m_s: float = NAN, speed_xy_m_s: float = NAN,
               want_takeoff: bool | None = None) -> Vec4:
        """Motor commands (0..1) for this tick.

        Optional constraints (PX4's vehicle_constraints, set by flight tasks such as takeoff): climb/descent/
        horizontal speed limits and `want_takeoff`; by default want_takeoff is computed from the setpoint as
        MulticopterPositionControl does in offboard (section 4.6): a setpoint above the vehicle, or climbing.
        """
        if self._registry.version != self._version:
            self._refresh()
        if not armed:
            return self._disarmed(now_us)
        if self._flying_reset:
            self.takeoff.update_state(True, landed, False, now_us, skip_takeoff=True)
            self._flying_reset = False
        if setpoint is None:
            self._pos_out = None
        if attitude_sp is not None:
            self.takeoff.update_state(armed, landed, False, now_us, skip_takeoff=True)
            q_sp, rates_sp, thrust = self._attitude_mode(state, attitude_sp)
            self._local_setpoint = self._local_out = None
        elif setpoint is not None:
            out = self._pos_out
            if out is None or now_us - self._pos_last_us >= POSITION_PERIOD_US - dt_s * 0.5e6:
                if out is None:
                    pos_dt = dt_s
                else:  # min(0.04, max(0.002, elapsed)), min/max as the exactly equivalent conditionals
                    pos_dt = (now_us - self._pos_last_us) * 1e-6
                    pos_dt = pos_dt if pos_dt > 0.002 else 0.002
                    pos_dt = pos_dt if pos_dt < 0.04 else 0.04
                out = self._position_mode(state, setpoint, landed, ground_contact, now_us, pos_dt,
                                          speed_up_m_s, speed_down_m_s, speed_xy_m_s, want_takeoff)
                self._pos_out, self._pos_last_us = out, now_us
            q_sp, thrust = out.q_sp, out.collective
            rates_sp = self.attitude.update(state.q_wxyz, q_sp, out.yawspeed_sp_rad_s)
        else:
            self.takeoff.update_state(armed, landed, False, now_us)
            self._idle()
            return ZERO4
        self._q_sp, self._rates_sp, self._thrust = q_sp, rates_sp, thrust
        torque = self.rate.update(state.rates_frd_rad_s, rates_sp, dt_s, landed, self._sat_pos, self._sat_neg)
        motors, self._sat_pos, self._sat_neg = mix(torque, thrust)
        return motors

    def _disarmed(self, now_us: int) -> Vec4:
        if self.takeoff.state != TakeoffState.DISARMED or self._thrust != 0.0:
            self.reset()
        self.takeoff.update_state(False, True, False, now_us)
        return ZERO4

    def _idle(self) -> None:
        self.position.reset_integral()
        self.rate.reset()
        self._local_setpoint, self._q_sp, self._rates_sp, self._thrust = None, None, (0.0, 0.0, 0.0), 0.0
        self._local_out = None

    def _attitude_mode(self, state: RigidBodyState, sp: AttitudeSetpoint) -> tuple[Vec4 | None, Vec3, float]:
        thrust = -sp.thrust_body[2] if isfinite(sp.thrust_body[2]) else 0.0
        thrust = thrust if thrust > 0.0 else 0.0  # min(1.0, max(0.0, thrust)) as exact conditionals
        thrust = thrust if thrust < 1.0 else 1.0
        q = sp.q_wxyz
        if q is not None and isfinite(q[0]) and isfinite(q[1]) and isfinite(q[2]) and isfinite(q[3]):
            q_sp = q_normalized(q)
            yaw_ff = sp.body_rates_rad_s[2] if math.isfinite(sp.body_rates_rad_s[2]) else 0.0
            return q_sp, self.attitude.update(state.q_wxyz, q_sp, yaw_ff), thrust
        r = sp.body_rates_rad_s
        rates = (r[0] if math.isfinite(r[0]) else 0.0, r[1] if math.isfinite(r[1]) else 0.0,
                 r[2] if math.isfinite(r[2]) else 0.0)
        return None, rates, thrust

    def _position_mode(self, state: RigidBodyState, sp: TrajectorySetpoint, landed: bool, ground_contact: bool,
                       now_us: int, dt_s: float, speed_up: float, speed_dn: float, speed_xy: float,
                       want_takeoff: bool | None) -> PositionOutput:
        """One position-control cycle (MulticopterPositionControl::Run). min/max of two floats are written as the
        exactly equivalent conditionals (min(a, b) is `b if b < a else a`, max(a, b) is `b if b > a else a`)."""
        s = self.settings.position
        if want_takeoff is None:
            want_takeoff = landed and _setpoint_wants_takeoff(sp, state.pos_ned_m[2])
        tko = self.takeoff.update_state(True, landed, want_takeoff, now_us)
        flying = tko >= _FLIGHT
        if not flying:
            sp = _without_acc_z(sp)
            self.position.set_hover_thrust(s.thr_hover)
        if tko < _RAMPUP or (flying and ground_contact):
            sp = IDLE_SETPOINT
            self.position.reset_integral()
        target = s.tilt_max_lnd_rad if tko < _FLIGHT else s.tilt_max_air_rad
        step = TILT_SLEW_RAD_S * dt_s
        tilt = self._tilt_limit
        hi, lo = tilt + step, tilt - step
        tilt = target if target < hi else hi  # min(tilt + step, target)
        tilt = self._tilt_limit = tilt if tilt > lo else lo  # max(tilt - step, ...)
        v_up, v_dn, v_xy = s.vel_max_up, s.vel_max_dn, s.vel_max_xy
        up = speed_up if speed_up - speed_up == 0.0 else v_up
        dn = speed_dn if speed_dn - speed_dn == 0.0 else v_dn
        xy = speed_xy if speed_xy - speed_xy == 0.0 else v_xy
        xy = 0.0 if xy < 0.0 else xy  # max(xy, 0)
        vel_xy = v_xy if v_xy < xy else xy  # min(..., MPC_XY_VEL_MAX)
        ramp = self.takeoff.update_ramp(dt_s, v_up if v_up < up else up)
        vel_up = v_up if v_up < ramp else ramp
        vel_dn = 0.0 if dn < 0.0 else dn
        yaw = yaw_from_q(state.q_wxyz)
        out = self.position.update_with(state.pos_ned_m, state.vel_ned_m_s, yaw, sp, dt_s, now_us, vel_xy, vel_up,
                                        vel_dn, tilt, s.thr_min if flying else 0.0, s.thr_max)
        self._in_failsafe = out.in_failsafe
        self._local_setpoint, self._local_out = None, out
        self._update_hover_thrust(state, out, landed, dt_s, now_us)
        return out

    def _update_hover_thrust(self, state: RigidBodyState, out: PositionOutput, landed: bool, dt_s: float,
                             now_us: int) -> None:
        """MulticopterHoverThrustEstimator: in the air (not landed, > 1 m up) feed the EKF; use it once valid."""
        if landed:
            self._hte_in_air = False
        elif -state.pos_ned_m[2] > 1.0:
            self._hte_in_air = True
        if not self._hte_in_air:
            self.hte.valid = False
            return
        valid = self.hte.update(-out.thrust_ned[2], -state.acc_ned_m_s2[2], state.vel_ned_m_s, dt_s, now_us)
        if valid and self.settings.position.use_hte:
            self.position.update_hover_thrust(self.hte.estimate, out.acceleration_sp_ned_m_s2[2])

    def _refresh(self) -> None:
        if self._registry.version == self._version:
            return
        self._version = self._registry.version
        self.settings = CascadeSettings.from_params(self._registry)
        self.position.settings = self.settings.position
        self.attitude.settings = self.settings.attitude
        self.rate.settings = self.settings.rate
        self.hte.settings = HoverThrustSettings.from_params(self._registry)
        self.takeoff.configure(self.settings.spoolup_time_s, self.settings.tko_ramp_t_s,
                               self.settings.position.vel_p[2])
        self._sat_pos = self._sat_neg = (False, False, False)


def _setpoint_wants_takeoff(sp: TrajectorySetpoint, z_m: float) -> bool:
    """MulticopterPositionControl offboard want_takeoff: setpoint above us, or climbing."""
    pz, vz, az = sp.position_ned_m[2], sp.velocity_ned_m_s[2], sp.acceleration_ned_m_s2[2]
    # isfinite(x) as `x - x == 0.0` (exact for floats; no call when compiled by `make speedups`)
    return (pz - pz == 0.0 and pz < z_m) or (vz - vz == 0.0 and vz < 0.0) or (az - az == 0.0 and az < 0.0)


def _without_acc_z(sp: TrajectorySetpoint) -> TrajectorySetpoint:
    a = sp.acceleration_ned_m_s2
    a2 = a[2]
    if a2 - a2 != 0.0:  # not isfinite(a2), exactly
        return sp
    return TrajectorySetpoint(sp.position_ned_m, sp.velocity_ned_m_s, (a[0], a[1], NAN), sp.yaw_rad, sp.yawspeed_rad_s)
