"""The multicopter control cascade the vehicle calls every physics tick.

trajectory setpoint -> PositionControl (with TakeoffHandling, as MulticopterPositionControl.cpp wraps it)
-> attitude setpoint -> AttitudeControl -> rate setpoint -> RateControl -> torque -> quad-X mixer -> motors 0..1.
An offboard attitude/rate setpoint (SET_ATTITUDE_TARGET) bypasses position control (PX4 then skips the takeoff
ramp: updateTakeoffState(..., skip_takeoff=true)). As MulticopterPositionControl::Run, the cascade chooses the
setpoint the position controller flies: the trajectory setpoint when it is valid (PositionControl's _inputValid),
else the last valid one for 200 ms, else the failsafe setpoint "stop and wait" (zero velocity,
MulticopterPositionControl::failsafe; the velocity estimate is always valid here).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Final

from sitl_emu.control.attitude import AttitudeControl, AttitudeControlSettings
from sitl_emu.control.hover import HoverThrustEstimator, HoverThrustSettings
from sitl_emu.control.mixer import mix
from sitl_emu.control.position import PositionControl, PositionControlSettings, PositionOutput, input_valid
from sitl_emu.control.qmath import constrain, isfinite, q_normalized, yaw_from_q
from sitl_emu.control.rate import RateControl, RateControlSettings
from sitl_emu.control.takeoff import TakeoffHandling, TakeoffState, before_ramp
from sitl_emu.physics import RigidBodyState
from sitl_emu.types import NAN, AttitudeSetpoint, TrajectorySetpoint, Vec3, Vec4

IDLE_SETPOINT: Final = TrajectorySetpoint(acceleration_ned_m_s2=(0.0, 0.0, 100.0))  # "no thrust" (not yet taken off)
TILT_SLEW_RAD_S: Final = 0.2  # MulticopterPositionControl _tilt_limit_slew_rate
# mc_pos_control runs on each vehicle_local_position update: EKF2 at 100 Hz (EKF2_PREDICT_US 10 ms) in PX4 SITL.
# Here every 8 ms (every second 250 Hz physics tick); attitude and rate control run every tick.
POSITION_PERIOD_US: Final = 8000
INVALID_HOLD_US: Final = 200_000  # MulticopterPositionControl LOITER_TIME_BEFORE_DESCEND hysteresis
FAILSAFE_SETPOINT: Final = TrajectorySetpoint(velocity_ned_m_s=(0.0, 0.0, 0.0))  # "Failsafe: stop and wait"


@dataclass(frozen=True, slots=True)
class CascadeSettings:
    position: PositionControlSettings = field(default_factory=PositionControlSettings)
    attitude: AttitudeControlSettings = field(default_factory=AttitudeControlSettings)
    rate: RateControlSettings = field(default_factory=RateControlSettings)
    hover: HoverThrustSettings = field(default_factory=HoverThrustSettings)
    spoolup_time_s: float = 1.0
    tko_ramp_t_s: float = 3.0


class MulticopterControl:
    """Position/attitude/rate cascade plus mixer. The owner (the vehicle) sets `settings` again when a parameter
    changes, as PX4's modules do on parameter_update."""

    def __init__(self, settings: CascadeSettings | None = None) -> None:
        self._local_setpoint: TrajectorySetpoint | None = None
        self._local_out: PositionOutput | None = None
        self.position = PositionControl()
        self.attitude = AttitudeControl()
        self.rate = RateControl()
        self.takeoff = TakeoffHandling()
        self.hte = HoverThrustEstimator()
        self._heading_of: RigidBodyState | None = None  # the state whose heading _heading_rad is (heading_rad)
        self._heading_rad = 0.0
        self.settings = settings or CascadeSettings()
        self.reset()

    @property
    def settings(self) -> CascadeSettings:
        return self._settings

    @settings.setter
    def settings(self, s: CascadeSettings) -> None:
        self._settings = s
        self.position.settings = s.position
        self.attitude.settings = s.attitude
        self.rate.settings = s.rate
        self.hte.settings = s.hover
        self.takeoff.configure(s.spoolup_time_s, s.tko_ramp_t_s, s.position.vel_p[2])
        self._sat_pos: tuple[bool, bool, bool] = (False, False, False)
        self._sat_neg: tuple[bool, bool, bool] = (False, False, False)

    def heading_rad(self, state: RigidBodyState) -> float:
        """The heading of `state`, worked out once per state: the navigator's task input and the position controller
        read the same estimate in a tick (a state is read-only by convention: ARCHITECTURE.md, On the tick path)."""
        if state is not self._heading_of:
            self._heading_of, self._heading_rad = state, yaw_from_q(state.q_wxyz)
        return self._heading_rad

    # --- telemetry -------------------------------------------------------------------------------------------
    @property
    def local_setpoint(self) -> TrajectorySetpoint | None:
        ls = self._local_setpoint
        if ls is None and self._local_out is not None:  # built on first read after a position-control cycle
            ls = self._local_setpoint = self._local_out.local_setpoint
        return ls

    @property
    def position_output(self) -> PositionOutput | None:
        """The last position-control cycle's output while position control runs (None when local_setpoint is None):
        what local_setpoint is built from, for a reader of a field or two (the navigator's input, the land
        detector's) that needs no setpoint object."""
        return self._local_out

    @property
    def attitude_setpoint_q_wxyz(self) -> Vec4 | None:
        return self._q_sp if self._has_q_sp else None

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
    def takeoff_state(self) -> TakeoffState:
        return self.takeoff.state

    @property
    def in_failsafe(self) -> bool:
        return self._in_failsafe

    # --- control -----------------------------------------------------------------------------------------------
    def reset(self, flying: bool = False) -> None:
        """Forget integrators and filters; `flying=True` starts in the FLIGHT takeoff state (vehicle already up)."""
        s = self._settings.position
        self.position.reset()
        self.position.set_hover_thrust(s.thr_hover)
        self.hte.reset()
        self._hte_in_air = False
        self.rate.reset()
        self._local_setpoint = None
        self._local_out = None  # the local setpoint's source, until it is built
        # the attitude setpoint, valid while _has_q_sp: a plain Vec4 stays unboxed in the compiled build, where an
        # optional one would be built as a Python tuple every tick
        self._q_sp: Vec4 = (1.0, 0.0, 0.0, 0.0)
        self._has_q_sp = False
        self._rates_sp: Vec3 = (0.0, 0.0, 0.0)
        self._thrust = 0.0
        self._in_failsafe = False
        self._last_valid: TrajectorySetpoint | None = None
        self._invalid_since_us: int | None = None
        self._pos_out: PositionOutput | None = None
        self._pos_last_us = 0
        self._tilt_limit = s.tilt_max_air_rad if flying else s.tilt_max_lnd_rad
        self._flying_reset = flying
        self.takeoff.state = TakeoffState.FLIGHT if flying else TakeoffState.DISARMED

    def update(self, state: RigidBodyState, setpoint: TrajectorySetpoint | None, attitude_sp: AttitudeSetpoint | None,
               armed: bool, landed: bool, now_us: int, dt_s: float, *, ground_contact: bool = False,
               want_takeoff: bool | None = None) -> Vec4:
        """Motor commands (0..1) for this tick.

        `want_takeoff` comes from the flight task in auto modes; by default it is computed from the setpoint as
        MulticopterPositionControl does in offboard (section 4.6): a setpoint above the vehicle, or climbing.
        """
        if not armed:
            return self._disarmed(now_us)
        if self._flying_reset:
            self.takeoff.update_state(True, landed, False, now_us, skip_takeoff=True)
            self._flying_reset = False
        if setpoint is None:
            self._pos_out = None
        if attitude_sp is not None:
            self.takeoff.update_state(armed, landed, False, now_us, skip_takeoff=True)
            q_att, rates_sp, thrust = self._attitude_mode(state, attitude_sp)
            self._has_q_sp = q_att is not None
            if q_att is not None:
                self._q_sp = q_att
            self._local_setpoint = self._local_out = None
        elif setpoint is not None:
            out = self._position_cycle(state, setpoint, landed, ground_contact, now_us, dt_s, want_takeoff)
            self._q_sp, self._has_q_sp, thrust = out.q_sp, True, out.collective
            rates_sp = self.attitude.update(state.q_wxyz, out.q_sp, out.yawspeed_sp_rad_s)
        else:
            self.takeoff.update_state(armed, landed, False, now_us)
            self._idle()
            return 0.0, 0.0, 0.0, 0.0  # motors off (a literal: a module tuple is a dict look-up, compiled)
        self._rates_sp, self._thrust = rates_sp, thrust
        torque = self.rate.update(state.rates_frd_rad_s, rates_sp, dt_s, landed, self._sat_pos, self._sat_neg)
        motors, self._sat_pos, self._sat_neg = mix(torque, thrust)
        return motors

    def _disarmed(self, now_us: int) -> Vec4:
        if self.takeoff.state is not TakeoffState.DISARMED or self._thrust != 0.0:
            self.reset()
        self.takeoff.update_state(False, True, False, now_us)
        return 0.0, 0.0, 0.0, 0.0  # motors off

    def _idle(self) -> None:
        self.position.reset_integral()
        self.rate.reset()
        self._local_setpoint, self._has_q_sp, self._rates_sp, self._thrust = None, False, (0.0, 0.0, 0.0), 0.0
        self._local_out = None

    def _attitude_mode(self, state: RigidBodyState, sp: AttitudeSetpoint) -> tuple[Vec4 | None, Vec3, float]:
        """An offboard attitude or body-rate setpoint: the attitude setpoint (None for rates), rates and thrust."""
        thrust = constrain(-sp.thrust_body[2] if isfinite(sp.thrust_body[2]) else 0.0, 0.0, 1.0)
        q, rates = sp.q_wxyz, sp.body_rates_rad_s
        if q is not None and isfinite(q[0]) and isfinite(q[1]) and isfinite(q[2]) and isfinite(q[3]):
            q_sp = q_normalized(q)
            yaw_ff = rates[2] if isfinite(rates[2]) else 0.0
            return q_sp, self.attitude.update(state.q_wxyz, q_sp, yaw_ff), thrust
        return None, (_finite_or_zero(rates[0]), _finite_or_zero(rates[1]), _finite_or_zero(rates[2])), thrust

    def _position_cycle(self, state: RigidBodyState, sp: TrajectorySetpoint, landed: bool, ground_contact: bool,
                        now_us: int, dt_s: float, want_takeoff: bool | None) -> PositionOutput:
        """The position controller's output, renewed every POSITION_PERIOD_US (on each local position estimate)."""
        out, last_us = self._pos_out, self._pos_last_us
        if out is not None and now_us - last_us < POSITION_PERIOD_US - dt_s * 0.5e6:
            return out
        pos_dt_s = dt_s if out is None else constrain((now_us - last_us) * 1e-6, 0.002, 0.04)
        out = self._position_mode(state, sp, landed, ground_contact, now_us, pos_dt_s, want_takeoff)
        self._pos_out, self._pos_last_us = out, now_us
        return out

    def _position_mode(self, state: RigidBodyState, sp: TrajectorySetpoint, landed: bool, ground_contact: bool,
                       now_us: int, dt_s: float, want_takeoff: bool | None) -> PositionOutput:
        """One position-control cycle (MulticopterPositionControl::Run)."""
        s = self._settings.position
        if want_takeoff is None:
            want_takeoff = landed and _setpoint_wants_takeoff(sp, state.pos_ned_m[2])
        tko = self.takeoff.update_state(True, landed, want_takeoff, now_us)
        flying = tko is TakeoffState.FLIGHT  # PX4's `>= flight`: the last state
        if not flying:
            sp = _without_acc_z(sp)
            self.position.set_hover_thrust(s.thr_hover)
        if before_ramp(tko) or (flying and ground_contact):
            sp = IDLE_SETPOINT
            self.position.reset_integral()
        self._set_limits(flying, dt_s)
        sp, self._in_failsafe = self._select_setpoint(sp, now_us)
        out = self.position.update(state.pos_ned_m, state.vel_ned_m_s, self.heading_rad(state), sp, dt_s)
        self._local_setpoint, self._local_out = None, out
        self._update_hover_thrust(state, out, landed, dt_s, now_us)
        return out

    def _select_setpoint(self, sp: TrajectorySetpoint, now_us: int) -> tuple[TrajectorySetpoint, bool]:
        """The setpoint to fly, and whether it is the failsafe's (module docstring)."""
        if sp is self._last_valid or input_valid(sp):  # the last valid setpoint (immutable) is still valid
            self._last_valid, self._invalid_since_us = sp, None
            return sp, False
        if self._invalid_since_us is None:
            self._invalid_since_us = now_us
        if self._last_valid is not None and now_us - self._invalid_since_us < INVALID_HOLD_US:
            return self._last_valid, False
        return FAILSAFE_SETPOINT, True

    def _set_limits(self, flying: bool, dt_s: float) -> None:
        """The position controller's limits for this cycle: the tilt limit slews (0.2 rad/s) from MPC_TILTMAX_LND to
        MPC_TILTMAX_AIR once flying, the climb limit follows the takeoff ramp, no minimum thrust before flight."""
        s = self._settings.position
        target = s.tilt_max_air_rad if flying else s.tilt_max_lnd_rad
        step = TILT_SLEW_RAD_S * dt_s
        self._tilt_limit = constrain(target, self._tilt_limit - step, self._tilt_limit + step)
        self.position.set_tilt_limit(self._tilt_limit)
        vel_up = self.takeoff.update_ramp(dt_s, s.vel_max_up)  # the takeoff ramp, then MPC_Z_VEL_MAX_UP
        self.position.set_velocity_limits(s.vel_max_xy, vel_up, s.vel_max_dn)
        self.position.set_thrust_limits(s.thr_min if flying else 0.0, s.thr_max)

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
        if valid and self._settings.position.use_hte:
            self.position.update_hover_thrust(self.hte.estimate, out.acceleration_sp_ned_m_s2[2])


def _setpoint_wants_takeoff(sp: TrajectorySetpoint, z_m: float) -> bool:
    """MulticopterPositionControl offboard want_takeoff: setpoint above us, or climbing."""
    pz, vz, az = sp.position_ned_m[2], sp.velocity_ned_m_s[2], sp.acceleration_ned_m_s2[2]
    return (isfinite(pz) and pz < z_m) or (isfinite(vz) and vz < 0.0) or (isfinite(az) and az < 0.0)


def _without_acc_z(sp: TrajectorySetpoint) -> TrajectorySetpoint:
    """Before flight no vertical acceleration feed-forward (MulticopterPositionControl: only the takeoff ramp)."""
    a = sp.acceleration_ned_m_s2
    if not isfinite(a[2]):
        return sp
    return TrajectorySetpoint(sp.position_ned_m, sp.velocity_ned_m_s, (a[0], a[1], NAN), sp.yaw_rad, sp.yawspeed_rad_s)


def _finite_or_zero(v: float) -> float:
    return v if isfinite(v) else 0.0
