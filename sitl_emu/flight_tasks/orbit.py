"""POSCTL.ORBIT: PX4's orbit flight task for a multicopter (MAV_CMD_DO_ORBIT).

Written from src/modules/flight_mode_manager/tasks/Orbit/FlightTaskOrbit.{hpp,cpp} and FlightModeManager.cpp:
- the task starts as a 1 m, 1 m/s clockwise orbit around the vehicle's own position, facing the centre
  (activate); the command then sets what it gives: param1 radius (its sign the direction; NaN/inf: keep), param2
  velocity (NaN/inf: keep; a negative one reverses), param3 ORBIT_YAW_BEHAVIOUR (5 UNCHANGED: MC_ORBIT_YAW_MOD before
  the orbit started), param5/6 centre and param7 altitude AMSL (NaN: keep);
- a radius outside [1 m, MC_ORBIT_RAD_MAX] fails the command: "Orbit radius limit exceeded", and FlightModeManager
  runs the failsafe task once (hold here, velocity 0) and then no task, so the position controller keeps that last
  setpoint while the mode stays Orbit (`FailedOrbitHold`); a later DO_ORBIT starts a new orbit;
- the velocity is clipped to MPC_XY_VEL_MAX and to the centripetal limit v^2 < 2 m/s^2 * r;
- off the circle (2 m radially, NAV_MC_ALT_RAD vertically) it flies to the nearest point of the circle at the
  centre's altitude with the position smoothing (MPC_XY_CRUISE), facing the centre; on it, the horizontal velocity
  is tangential (slew-limited by MPC_ACC_HOR from 0) plus a radial correction, the altitude is the manual altitude
  task's (throttle), the yaw per the behaviour, smoothed with MPC_YAWRAUTO_MAX / MPC_YAWRAUTO_ACC;
- the sticks adjust radius (pitch; roll when facing the tangent) and velocity (roll, the v1.15/v1.16 sign: right
  slows a clockwise orbit; pitch when tangent);
- every update publishes orbit_status (ORBIT_EXECUTION_STATUS): radius signed by the direction, centre, altitude.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final

from sitl_emu.control.qmath import constrain, isfinite
from sitl_emu.flight_tasks.manual import TASK_PERIOD_US, ManualAltitudeTask, ManualSettings, VerticalSmoothing
from sitl_emu.flight_tasks.sticks import stick_expo
from sitl_emu.geo import GeoRef, global_to_ned, ned_to_global
from sitl_emu.motion_planning.heading import HeadingSmoother
from sitl_emu.motion_planning.smoothing import PositionSmoother
from sitl_emu.navigator.commands import NavCommand
from sitl_emu.navigator.setpoint import NavInput, SetpointType
from sitl_emu.params import ParamRegistry
from sitl_emu.px4 import Severity
from sitl_emu.types import NAN, NAN3, OrbitStatus, TrajectorySetpoint, Vec3

RADIUS_MIN_M: Final = 1.0  # FlightTaskOrbit.hpp _radius_min
ACCELERATION_MAX_M_S2: Final = 2.0  # _acceleration_max: the centripetal limit
ON_CIRCLE_M: Final = 2.0  # _horizontal_acceptance_radius
YAW_UNCHANGED: Final = 5  # ORBIT_YAW_BEHAVIOUR_UNCHANGED
FRONT_TO_CENTRE, INITIAL_HEADING, UNCONTROLLED, FRONT_TANGENT, RC_CONTROLLED = 0, 1, 2, 3, 4
RADIUS_TEXT: Final = "Orbit radius limit exceeded"


@dataclass(frozen=True, slots=True)
class OrbitSettings:
    rad_max: float
    yaw_mod: int
    xy_cruise: float
    acc_hor: float
    xy_vel_max: float
    xy_err_max: float
    jerk: float
    acc_up: float
    acc_down: float
    z_v_auto_up: float
    z_v_auto_dn: float
    alt_rad: float
    yawrate_max: float
    yawacc_max: float

    @classmethod
    def from_params(cls, p: ParamRegistry) -> OrbitSettings:
        def f(name: str) -> float:
            return float(p[name])

        return cls(f("MC_ORBIT_RAD_MAX"), int(p["MC_ORBIT_YAW_MOD"]), f("MPC_XY_CRUISE"), f("MPC_ACC_HOR"),
                   f("MPC_XY_VEL_MAX"), f("MPC_XY_ERR_MAX"), f("MPC_JERK_AUTO"), f("MPC_ACC_UP_MAX"),
                   f("MPC_ACC_DOWN_MAX"), f("MPC_Z_V_AUTO_UP"), f("MPC_Z_V_AUTO_DN"), f("NAV_MC_ALT_RAD"),
                   math.radians(f("MPC_YAWRAUTO_MAX")), math.radians(f("MPC_YAWRAUTO_ACC")))


def sanitize(radius: float, velocity: float, o: OrbitSettings) -> tuple[float, float]:
    """_sanitizeParams: radius into range, velocity within MPC_XY_VEL_MAX and the centripetal limit."""
    radius = constrain(radius, RADIUS_MIN_M, o.rad_max)
    velocity = constrain(velocity, -abs(o.xy_vel_max), abs(o.xy_vel_max))
    if velocity * velocity >= ACCELERATION_MAX_M_S2 * radius:
        velocity = math.copysign(math.sqrt(ACCELERATION_MAX_M_S2 * radius), velocity) if velocity else 0.0
    return radius, velocity


class OrbitTask(ManualAltitudeTask):
    """One activation of FlightTaskOrbit (FlightTaskManualAltitudeSmoothVel gives the altitude on the circle)."""

    def __init__(self, nav: NavInput, params: ParamRegistry) -> None:
        super().__init__(nav, params)
        self.o = OrbitSettings.from_params(params)
        self.radius_m, self.velocity_m_s = RADIUS_MIN_M, 1.0
        self.centre_ned_m: Vec3 = nav.pos_ned_m
        self.yaw_behaviour = FRONT_TO_CENTRE
        self._clockwise_start, self._orbiting, self._approaching = True, False, True
        self._initial_heading = nav.yaw_rad
        sp = nav.vel_sp_ned_m_s
        vel = tuple(sp[i] if isfinite(sp[i]) else nav.vel_ned_m_s[i] for i in range(3))
        self._approach = PositionSmoother((0.0, 0.0, 0.0), vel, nav.pos_ned_m)  # type: ignore[arg-type]
        self._heading = HeadingSmoother(nav.yaw_rad, 0.0)
        self._slew_m_s = 0.0  # SlewRate on the tangential velocity
        self._last: TrajectorySetpoint = TrajectorySetpoint()
        self._messages: list[tuple[Severity, str]] = []
        self.status_time_us = nav.time_us

    # ---- the command ---------------------------------------------------------------------------------------------
    def apply(self, cmd: NavCommand, centre_ned_m: Vec3, nav: NavInput) -> bool:
        """applyCommandParameters: False if the command failed (radius out of range)."""
        clockwise, radius, speed = self.velocity_m_s > 0.0, self.radius_m, abs(self.velocity_m_s)
        if isfinite(cmd.radius_m):
            clockwise, radius = cmd.radius_m > 0.0, abs(cmd.radius_m)
        if isfinite(cmd.speed_m_s):
            speed = cmd.speed_m_s
        ok = RADIUS_MIN_M <= radius <= self.o.rad_max
        if ok:
            self._clockwise_start = clockwise
            self.radius_m, self.velocity_m_s = sanitize(radius, speed if clockwise else -speed, self.o)
        else:
            self._messages.append((Severity.CRITICAL, RADIUS_TEXT))
        self._yaw_behaviour(cmd.yaw_behaviour)
        self._initial_heading = nav.yaw_rad
        x, y, z = self.centre_ned_m
        if isfinite(centre_ned_m[0]) and isfinite(centre_ned_m[1]):
            x, y = centre_ned_m[0], centre_ned_m[1]
        self.centre_ned_m = (x, y, centre_ned_m[2] if isfinite(centre_ned_m[2]) else z)
        if not self._on_circle(nav) and not self._approaching:
            self._approaching = True
            last = self._last
            self._approach.reset(_or(last.acceleration_ned_m_s2, (0.0, 0.0, 0.0)),
                                 _or(last.velocity_ned_m_s, nav.vel_ned_m_s), nav.pos_ned_m)
        return ok

    def _yaw_behaviour(self, value: float) -> None:
        if not isfinite(value):
            return
        behaviour = int(value)  # the float is stored in an int (truncation); lround only for the UNCHANGED test
        if (int(math.copysign(math.floor(abs(value) + 0.5), value)) & 0xFF) == YAW_UNCHANGED:  # (uint8_t)lround
            if not self._orbiting:
                self.yaw_behaviour = self.o.yaw_mod
        else:
            self.yaw_behaviour = behaviour

    # ---- the cycle -----------------------------------------------------------------------------------------------
    def update(self, nav: NavInput, dt_s: float) -> TrajectorySetpoint:
        self._orbiting = True
        if self._params.version != self._version:  # ManualAltitudeTask.update re-reads its own settings
            self._version, self.o = self._params.version, OrbitSettings.from_params(self._params)
            self.s = ManualSettings.from_params(self._params)
        self._adjust_by_sticks(dt_s)
        if self._approaching and self._on_circle(nav):
            self._approaching = False
            self._slew_m_s = 0.0
            last = self._last
            self._z = VerticalSmoothing(_first(last.acceleration_ned_m_s2[2], 0.0),
                                        _first(last.velocity_ned_m_s[2], nav.vel_ned_m_s[2]),
                                        _first(last.position_ned_m[2], nav.pos_ned_m[2]))
        sp = self._approach_setpoint(nav, dt_s) if self._approaching else super().update(nav, dt_s)
        sp = self._smooth_heading(nav, sp, dt_s)
        self._last, self.status_time_us = sp, nav.time_us
        return sp

    def _on_circle(self, nav: NavInput) -> bool:
        c, p = self.centre_ned_m, nav.pos_ned_m
        return (abs(math.hypot(p[0] - c[0], p[1] - c[1]) - self.radius_m) < ON_CIRCLE_M
                and abs(p[2] - c[2]) < self.o.alt_rad)

    def _adjust_by_sticks(self, dt_s: float) -> None:
        """_adjustParametersByStick: pitch changes the radius, roll the speed (swapped when facing the tangent)."""
        o, dz = self.o, self.s.deadzone
        pitch, roll = stick_expo(self.sticks.pitch, dz), stick_expo(self.sticks.roll, dz)
        radius, velocity = self.radius_m, self.velocity_m_s
        if self.yaw_behaviour == FRONT_TANGENT:
            sign = 1.0 if self._clockwise_start else -1.0
            radius -= sign * roll * dt_s * o.xy_cruise
            velocity += sign * pitch * dt_s * o.acc_hor
        else:
            radius -= pitch * dt_s * o.xy_cruise
            velocity -= roll * dt_s * o.acc_hor  # V: PX4 v1.15/v1.16; main (Dec 2025, 8c532db6b3) adds the roll
        self.radius_m, self.velocity_m_s = sanitize(radius, velocity, o)

    def _approach_setpoint(self, nav: NavInput, dt_s: float) -> TrajectorySetpoint:
        """_generate_circle_approach_setpoints: to the nearest point of the circle, at the centre's altitude."""
        o, sm, c, p = self.o, self._approach, self.centre_ned_m, nav.pos_ned_m
        dx, dy = c[0] - p[0], c[1] - p[1]
        dist = math.hypot(dx, dy)
        ux, uy = (dx / dist, dy / dist) if dist > 0.0 else (0.0, 0.0)
        target = (p[0] + ux * (dist - self.radius_m), p[1] + uy * (dist - self.radius_m), c[2])
        sm.cruise_speed_m_s, sm.max_xy_error_m = o.xy_cruise, o.xy_err_max
        going_up = isfinite(self._last.velocity_ned_m_s[2]) and self._last.velocity_ned_m_s[2] < 0.0
        acc_z, vel_z = (o.acc_up, o.z_v_auto_up) if going_up else (o.acc_down, o.z_v_auto_dn)
        sm.set_limits(o.jerk, o.acc_hor, acc_z, o.xy_vel_max, vel_z)
        sm.update(p, target, NAN3, dt_s)
        ax, ay, az = sm.axes
        yaw = math.atan2(dy, dx)
        return TrajectorySetpoint((ax.x, ay.x, az.x), (ax.v, ay.v, az.v), (ax.a, ay.a, az.a), yaw, NAN)

    def _horizontal(self, nav: NavInput, yaw_sp: float, dt_s: float, z: tuple[float, float, float],
                    yawspeed: float) -> TrajectorySetpoint:
        """On the circle: _generate_circle_setpoints and _generate_circle_yaw_setpoints (yaw_sp / yawspeed are the
        altitude task's, from the yaw stick: kept for RC_CONTROLLED)."""
        c, p, r = self.centre_ned_m, nav.pos_ned_m, self.radius_m
        rx, ry = p[0] - c[0], p[1] - c[1]
        dist = math.hypot(rx, ry)
        ux, uy = (rx / dist, ry / dist) if dist > 0.0 else (0.0, 0.0)
        step = self.o.acc_hor * dt_s
        self._slew_m_s = constrain(self.velocity_m_s, self._slew_m_s - step, self._slew_m_s + step)
        v = self._slew_m_s
        vx, vy = -uy * v + (r - dist) * ux, ux * v + (r - dist) * uy
        acc = v * v / r
        yaw_sp, yawspeed = self._circle_yaw(rx, ry, yaw_sp, yawspeed)
        return TrajectorySetpoint((NAN, NAN, z[0]), (vx, vy, z[1]), (-ux * acc, -uy * acc, z[2]), yaw_sp, yawspeed)

    def _circle_yaw(self, rx: float, ry: float, stick_yaw: float, stick_rate: float) -> tuple[float, float]:
        behaviour, rate = self.yaw_behaviour, self.velocity_m_s / self.radius_m
        if behaviour == INITIAL_HEADING:
            return self._initial_heading, NAN
        if behaviour == UNCONTROLLED:
            return NAN, 0.0
        if behaviour == FRONT_TANGENT:
            sign = 1.0 if self._clockwise_start else -1.0
            return math.atan2(sign * rx, -sign * ry), rate
        if behaviour == RC_CONTROLLED:
            return stick_yaw, stick_rate
        return math.atan2(-ry, -rx), rate

    def _smooth_heading(self, nav: NavInput, sp: TrajectorySetpoint, dt_s: float) -> TrajectorySetpoint:
        """HeadingSmoothing on the yaw setpoint; its rate is the feed-forward only while approaching."""
        h = self._heading
        if not isfinite(sp.yaw_rad):
            h.reset(nav.yaw_rad, 0.0)
            return sp
        h.set_limits(self.o.yawrate_max, self.o.yawacc_max)
        h.update(sp.yaw_rad, dt_s)
        rate = h.rate_rad_s if self._approaching else sp.yawspeed_rad_s
        return TrajectorySetpoint(sp.position_ned_m, sp.velocity_ned_m_s, sp.acceleration_ned_m_s2, h.heading_rad,
                                  rate)

    # ---- what it reports -------------------------------------------------------------------------------------------
    def status(self, ref: GeoRef) -> OrbitStatus:
        """orbit_status (sendTelemetry): the altitude of the altitude setpoint, or the vehicle's while it moves."""
        lat, lon, _ = ned_to_global(ref, self.centre_ned_m)
        z = self._last.position_ned_m[2]
        if not isfinite(z):
            z = self._z_now
        sign = -1.0 if self.velocity_m_s < 0.0 else 1.0
        return OrbitStatus(self.status_time_us, sign * self.radius_m, lat, lon, ref.alt_amsl_m - z, self.yaw_behaviour)

    @property
    def _z_now(self) -> float:
        return self._approach.axes[2].x if self._approaching else self._z.axis.x

    def drain_messages(self) -> list[tuple[Severity, str]]:
        out, self._messages = self._messages, []
        return out


class FailedOrbitHold:
    """What flies after a failed DO_ORBIT: FlightTaskFailsafe's one setpoint (here, velocity 0, thrust-neutral
    acceleration), which the position controller keeps once FlightModeManager runs no task."""

    period_us = TASK_PERIOD_US
    finished = False
    want_takeoff = False
    setpoint_type = SetpointType.POSITION

    def __init__(self, nav: NavInput, messages: list[tuple[Severity, str]]) -> None:
        self._sp = TrajectorySetpoint(nav.pos_ned_m, (0.0, 0.0, 0.0), (0.0, 0.0, NAN), nav.yaw_rad, 0.0)
        self._messages = messages

    def update(self, nav: NavInput, dt_s: float) -> TrajectorySetpoint:
        return self._sp

    def drain_messages(self) -> list[tuple[Severity, str]]:
        out, self._messages = self._messages, []
        return out


OrbitFlight = OrbitTask | FailedOrbitHold


def command_centre(cmd: NavCommand, ref: GeoRef) -> Vec3:
    """The commanded centre in NED; NaN components are not given (lat and lon only both together)."""
    x = y = NAN
    if isfinite(cmd.lat_deg) and isfinite(cmd.lon_deg):
        x, y, _ = global_to_ned(ref, cmd.lat_deg, cmd.lon_deg, ref.alt_amsl_m)
    z = ref.alt_amsl_m - cmd.alt_amsl_m if isfinite(cmd.alt_amsl_m) else NAN
    return x, y, z


def apply_orbit(task: OrbitFlight | None, cmd: NavCommand | None, nav: NavInput, params: ParamRegistry,
                ref: GeoRef) -> OrbitFlight:
    """FlightModeManager: start the orbit task (after a failed command, a new one), apply the command; a failed
    command leaves the failsafe hold."""
    if not isinstance(task, OrbitTask):
        task = OrbitTask(nav, params)
    if cmd is None or task.apply(cmd, command_centre(cmd, ref), nav):
        return task
    return FailedOrbitHold(nav, task.drain_messages())


def _or(v: Vec3, fallback: Vec3) -> Vec3:
    return tuple(v[i] if isfinite(v[i]) else fallback[i] for i in range(3))  # type: ignore[return-value]


def _first(value: float, fallback: float) -> float:
    return value if isfinite(value) else fallback
