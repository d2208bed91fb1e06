"""The manual modes' flight tasks: Altitude (ALTCTL) and Position (POSCTL, MPC_POS_MODE 4), and Stabilized's stick
mapping. The sticks are the last manual input (commander/manual_control.py), set on the task before each update.

After PX4's flight_mode_manager tasks FlightTaskManualAltitude -> FlightTaskManualAltitudeSmoothVel ->
FlightTaskManualAcceleration (src/modules/flight_mode_manager/tasks/...), motion_planning/ManualVelocitySmoothingZ
and mc_att_control's generate_attitude_setpoint (Stabilized). Per cycle (FlightModeManager, 50 Hz):
- vertical: the throttle around its centre commands a climb rate (deadzone, expo; MPC_Z_VEL_MAX_UP/DN), slowed near
  the ground (MPC_TKO_SPEED up and MPC_LAND_SPEED down below MPC_LAND_ALT2, blended up to MPC_LAND_ALT1), smoothed
  with jerk and acceleration limits; with the throttle centred the altitude locks where the vehicle is once it climbs
  slower than MPC_HOLD_MAX_Z (or the smoothing has come to rest), and the mode starts locked at the altitude it was
  entered at (FlightTaskManualAltitude::_updateAltitudeLock, activate);
- activation: from the previous task's last setpoint (FlightModeManager::switchTask hands it over), the vehicle's
  state where there is none;
- heading: the yaw stick commands a yaw rate (flight_tasks/sticks.py StickYaw);
- horizontal: Position mode's acceleration sticks with a position lock, or Altitude mode's tilt sticks;
- takeoff: the throttle above 0.3 asks for it (vehicle_constraints.want_takeoff); until the controller's takeoff
  ramp has begun the task restarts every cycle from the vehicle, as FlightModeManager re-activates it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final

from sitl_emu.commander.manual_control import CENTRED
from sitl_emu.control.qmath import constrain, isfinite
from sitl_emu.control.takeoff import TakeoffState, before_ramp
from sitl_emu.flight_tasks.sticks import (
    FLT_EPSILON,
    NAN,
    StickAccelerationXY,
    StickXYSettings,
    StickYaw,
    stick_expo,
    stick_tilt_acceleration,
)
from sitl_emu.motion_planning.smoothing import AxisSmoother
from sitl_emu.navigator.setpoint import NavInput, SetpointType
from sitl_emu.params import ParamRegistry
from sitl_emu.px4 import Severity
from sitl_emu.types import ManualControlSetpoint, TrajectorySetpoint

TASK_PERIOD_US: Final = 20_000  # FlightModeManager's vehicle_local_position interval: 50 Hz
WANT_TAKEOFF_THROTTLE: Final = 0.3  # FlightTaskManualAltitude::_checkTakeoff
LOCK_VEL_M_S: Final = 0.1  # ManualVelocitySmoothingZ::checkPositionLock
LOCK_ACC_M_S2: Final = 0.2


@dataclass(frozen=True, slots=True)
class ManualSettings:
    """The manual tasks' parameters (mc_pos_control, manual_control yaml names)."""

    deadzone: float  # MAN_DEADZONE
    vel_up: float  # MPC_Z_VEL_MAX_UP
    vel_dn: float  # MPC_Z_VEL_MAX_DN
    acc_up: float  # MPC_ACC_UP_MAX
    acc_down: float  # MPC_ACC_DOWN_MAX
    jerk: float  # MPC_JERK_MAX
    tko_speed: float  # MPC_TKO_SPEED
    land_speed: float  # MPC_LAND_SPEED
    land_alt1: float  # MPC_LAND_ALT1
    land_alt2: float  # MPC_LAND_ALT2
    hold_max_z: float  # MPC_HOLD_MAX_Z
    yaw_rate_rad_s: float  # MPC_MAN_Y_MAX
    yaw_tau_s: float  # MPC_MAN_Y_TAU
    tilt_max_rad: float  # MPC_MAN_TILT_MAX
    tilt_air_rad: float  # MPC_TILTMAX_AIR
    tilt_lnd_rad: float  # MPC_TILTMAX_LND
    xy: StickXYSettings

    @classmethod
    def from_params(cls, p: ParamRegistry) -> ManualSettings:
        def f(name: str) -> float:
            return float(p[name])

        return cls(
            deadzone=f("MAN_DEADZONE"), vel_up=f("MPC_Z_VEL_MAX_UP"), vel_dn=f("MPC_Z_VEL_MAX_DN"),
            acc_up=f("MPC_ACC_UP_MAX"), acc_down=f("MPC_ACC_DOWN_MAX"), jerk=f("MPC_JERK_MAX"),
            tko_speed=f("MPC_TKO_SPEED"), land_speed=f("MPC_LAND_SPEED"), land_alt1=f("MPC_LAND_ALT1"),
            land_alt2=f("MPC_LAND_ALT2"), hold_max_z=f("MPC_HOLD_MAX_Z"),
            yaw_rate_rad_s=math.radians(f("MPC_MAN_Y_MAX")), yaw_tau_s=f("MPC_MAN_Y_TAU"),
            tilt_max_rad=math.radians(f("MPC_MAN_TILT_MAX")), tilt_air_rad=math.radians(f("MPC_TILTMAX_AIR")),
            tilt_lnd_rad=math.radians(f("MPC_TILTMAX_LND")),
            xy=StickXYSettings(vel_manual=f("MPC_VEL_MANUAL"), vel_side=f("MPC_VEL_MAN_SIDE"),
                               vel_back=f("MPC_VEL_MAN_BACK"), acc_hor=f("MPC_ACC_HOR"), jerk_max=f("MPC_JERK_MAX")),
        )


def _interp(x: float, x_lo: float, x_hi: float, y_lo: float, y_hi: float) -> float:
    """math::interpolate: y_lo below x_lo, y_hi above x_hi, linear between."""
    if x <= x_lo:
        return y_lo
    if x > x_hi:
        return y_hi
    return y_lo + (x - x_lo) / (x_hi - x_lo) * (y_hi - y_lo)


class VerticalSmoothing:
    """ManualVelocitySmoothingZ: a jerk-limited climb rate towards the stick's, and its own altitude lock."""

    def __init__(self, acc: float, vel: float, pos: float) -> None:
        self.axis = AxisSmoother(acc, vel, pos)
        self.locked_z = NAN

    def update(self, s: ManualSettings, target_vz: float, z: float, vz_feedback: float, dt_s: float) -> None:
        axis = self.axis
        axis.update_traj(dt_s)
        up = target_vz < 0.0
        axis.max_jerk = s.jerk
        axis.max_accel, axis.max_vel = (s.acc_up, s.vel_up) if up else (s.acc_down, s.vel_dn)
        if abs(axis.v) < LOCK_VEL_M_S and abs(axis.a) < LOCK_ACC_M_S2 and abs(target_vz) <= FLT_EPSILON:
            if not isfinite(self.locked_z):
                self.locked_z = axis.x
        else:
            if isfinite(self.locked_z):  # unlock from the controller's climb rate, so nothing jumps
                axis.v = vz_feedback if isfinite(vz_feedback) else axis.v
                self.locked_z = NAN
            axis.set_position(z)
        axis.update_durations(target_vz)


def altitude_lock(locked_z: float, throttle_centred: bool, stopped: bool, z: float) -> float:
    """FlightTaskManualAltitude::_updateAltitudeLock (heights from the local origin, MPC_ALT_MODE 0): with the throttle
    centred the altitude locks where the vehicle is once it climbs or sinks slower than MPC_HOLD_MAX_Z (`stopped`), and
    a lock (also the one the mode starts with) holds while the throttle stays centred; any throttle frees it (NaN)."""
    if not throttle_centred:
        return NAN
    if isfinite(locked_z):
        return locked_z
    return z if stopped else NAN


def _last_or(value: float, fallback: float) -> float:
    return value if isfinite(value) else fallback


class ManualAltitudeTask:
    """ALTCTL (FlightTaskManualAltitudeSmoothVel): climb rate from the throttle, tilt from the right stick."""

    period_us = TASK_PERIOD_US
    finished = False

    @property
    def setpoint_type(self) -> SetpointType:
        """A position-controlled setpoint (not a navigator takeoff or land item)."""
        return SetpointType.POSITION

    def __init__(self, nav: NavInput, params: ParamRegistry, last: TrajectorySetpoint | None = None) -> None:
        """`last`: the setpoint of the task that ran before (FlightModeManager hands it to activate()); None (or NaN
        components) after a mode without one, when the vehicle's state stands in."""
        self._params, self._version = params, params.version
        self.s = ManualSettings.from_params(params)
        self.sticks: ManualControlSetpoint = CENTRED
        self.want_takeoff = False
        self._yaw = StickYaw(self.s.yaw_rate_rad_s, self.s.yaw_tau_s)
        self._z: VerticalSmoothing
        self._locked_z = NAN
        self._activate(nav, last if last is not None else TrajectorySetpoint())

    def _activate(self, nav: NavInput, last: TrajectorySetpoint) -> None:
        """activate(last_setpoint): the altitude locked where the vehicle is (FlightTaskManualAltitude), the vertical
        smoothing from the last setpoint's height, climb rate and acceleration (FlightTaskManualAltitudeSmoothVel)."""
        self._yaw.reset()
        z = nav.pos_ned_m[2]
        self._locked_z = z
        self._z = VerticalSmoothing(_last_or(last.acceleration_ned_m_s2[2], 0.0),
                                    _last_or(last.velocity_ned_m_s[2], nav.vel_ned_m_s[2]),
                                    _last_or(last.position_ned_m[2], z))

    def update(self, nav: NavInput, dt_s: float) -> TrajectorySetpoint:
        if self._params.version != self._version:
            self._version, self.s = self._params.version, ManualSettings.from_params(self._params)
        sticks, s = self.sticks, self.s
        yaw_sp, yawspeed = self._yaw.update(stick_expo(sticks.yaw, s.deadzone), nav.yaw_rad, dt_s)
        locked_z = self._update_altitude_lock(nav)
        target_vz = self._ground_slowdown(nav, self._climb_rate(sticks.throttle))
        self._z.update(s, target_vz, nav.pos_ned_m[2], nav.vel_sp_ned_m_s[2], dt_s)
        if not isfinite(locked_z):  # _setOutputState: the smoothing's own lock, if it has one
            locked_z = self._locked_z = self._z.locked_z
        self.want_takeoff = sticks.throttle > WANT_TAKEOFF_THROTTLE
        axis = self._z.axis
        sp = self._horizontal(nav, yaw_sp, dt_s, (locked_z, axis.v, axis.a), yawspeed)
        if before_ramp(nav.takeoff_state):  # FlightModeManager re-activates the task until the ramp
            self._activate(nav, TrajectorySetpoint(velocity_ned_m_s=(NAN, NAN, axis.v),
                                                   acceleration_ned_m_s2=(0.0, 0.0, 0.0)))  # FlightTask::reActivate
        return sp

    def _update_altitude_lock(self, nav: NavInput) -> float:
        s = self.s
        centred = abs(stick_expo(self.sticks.throttle, s.deadzone)) <= FLT_EPSILON
        stopped = s.hold_max_z < FLT_EPSILON or abs(nav.vel_ned_m_s[2]) < s.hold_max_z
        self._locked_z = altitude_lock(self._locked_z, centred, stopped, nav.pos_ned_m[2])
        return self._locked_z

    def _horizontal(self, nav: NavInput, yaw_sp: float, dt_s: float, z: tuple[float, float, float],
                    yawspeed: float) -> TrajectorySetpoint:
        """ALTCTL: the sticks tilt the vehicle (an acceleration setpoint); no horizontal position or velocity."""
        ax, ay = stick_tilt_acceleration((self.sticks.pitch, self.sticks.roll),
                                         yaw_sp if isfinite(yaw_sp) else nav.yaw_rad, self.s.tilt_max_rad)
        return TrajectorySetpoint((NAN, NAN, z[0]), (NAN, NAN, z[1]), (ax, ay, z[2]), yaw_sp, yawspeed)

    def _climb_rate(self, throttle: float) -> float:
        """_scaleSticks: NED, so up is negative; the side (up or down limit) from the raw throttle."""
        limit = self.s.vel_dn if throttle < 0.0 else self.s.vel_up
        return -stick_expo(throttle, self.s.deadzone) * limit

    def _ground_slowdown(self, nav: NavInput, vz: float) -> float:
        """_respectGroundSlowdown: slower climbs and descents near the ground (distance above home)."""
        s = self.s
        dist = -(nav.pos_ned_m[2] - nav.home_ned_m[2])
        limit_down = _interp(dist, s.land_alt2, s.land_alt1, s.land_speed, s.vel_dn)
        limit_up = _interp(dist, s.land_alt2, s.land_alt1, s.tko_speed, s.vel_up)
        return constrain(vz, -limit_up, limit_down)

    def drain_messages(self) -> list[tuple[Severity, str]]:
        return []


class ManualPositionTask(ManualAltitudeTask):
    """POSCTL with MPC_POS_MODE 4 (FlightTaskManualAcceleration): the sticks command an acceleration."""

    _xy: StickAccelerationXY

    def _activate(self, nav: NavInput, last: TrajectorySetpoint) -> None:
        """FlightTaskManualAcceleration::activate: the horizontal velocity and acceleration from the last setpoint
        (the vehicle's velocity and no acceleration where it has none); no position lock yet."""
        super()._activate(nav, last)
        (vx, vy, _), (ax, ay, _) = last.velocity_ned_m_s, last.acceleration_ned_m_s2
        vel = (vx, vy) if isfinite(vx) and isfinite(vy) else (nav.vel_ned_m_s[0], nav.vel_ned_m_s[1])
        self._xy = StickAccelerationXY(self.s.xy, vel, (ax, ay) if isfinite(ax) and isfinite(ay) else (0.0, 0.0))

    def _horizontal(self, nav: NavInput, yaw_sp: float, dt_s: float, z: tuple[float, float, float],
                    yawspeed: float) -> TrajectorySetpoint:
        s, sticks, xy = self.s, self.sticks, self._xy
        tilt = s.tilt_air_rad if nav.takeoff_state is TakeoffState.FLIGHT else s.tilt_lnd_rad
        xy.update((stick_expo(sticks.pitch, s.deadzone), stick_expo(sticks.roll, s.deadzone)), nav.yaw_rad, yaw_sp,
                  (nav.pos_ned_m[0], nav.pos_ned_m[1]), (nav.vel_sp_ned_m_s[0], nav.vel_sp_ned_m_s[1]), dt_s, tilt)
        (px, py), (vx, vy), (ax, ay) = xy.pos_sp, xy.vel_sp, xy.acc_sp
        return TrajectorySetpoint((px, py, z[0]), (vx, vy, z[1]), (ax, ay, z[2]), yaw_sp, yawspeed)
