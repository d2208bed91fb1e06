"""AUTO.FOLLOW_TARGET: PX4's follow-target flight task for a multicopter.

Written from src/modules/flight_mode_manager/tasks/AutoFollowTarget/FlightTaskAutoFollowTarget.{hpp,cpp}:
- the target estimate (flight_tasks/follow_estimator.py) is smoothed by a second-order reference model (1 rad/s, damping
  0.7071) that gives a kinematically feasible target position and velocity;
- the vehicle keeps FLW_TGT_DST from the target at the angle FLW_TGT_FA (0 in front of the target's course, clockwise,
  180 behind) around it; the orbit angle around the target follows the target's course (tracked only while the
  target moves at 1 m/s or more) with a jerk-limited trajectory (4 m/s^3, 2 m/s^2, FLW_TGT_MAX_VEL tangentially);
- the height is FLW_TGT_HT above home (FLW_TGT_ALT_M 0), above the ground (1; flat ground here) or above the target
  (2); while more than 3 m off that height it only climbs or descends, holding its horizontal position;
- it faces the target when farther than 1 m; below 1 m above the ground it climbs at 0.5 m/s (emergency ascent);
- without a valid estimate (no fix yet, or a fix with a NaN altitude) it holds still: no position, velocity 0;
  when the fixes stop, the estimate stops moving after 3 s and the vehicle keeps station at the last known place;
- the sticks adjust height (throttle), distance (pitch) and angle (roll); the mode is not auto-enabled, so moving
  them never hands over to Position.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final

from sitl_emu.commander.manual_control import CENTRED
from sitl_emu.control.qmath import constrain, isfinite
from sitl_emu.flight_tasks.follow_estimator import TargetEstimate, TargetEstimator, TargetFix
from sitl_emu.flight_tasks.manual import TASK_PERIOD_US
from sitl_emu.flight_tasks.sticks import stick_expo
from sitl_emu.motion_planning.heading import wrap_pi
from sitl_emu.motion_planning.smoothing import AxisSmoother, max_speed_from_distance
from sitl_emu.navigator.setpoint import NavInput, SetpointType
from sitl_emu.params import ParamRegistry
from sitl_emu.px4 import Severity
from sitl_emu.types import NAN, NAN3, ManualControlSetpoint, TrajectorySetpoint, Vec3

MIN_SAFETY_ALT_M: Final = 1.0
EMERGENCY_ASCENT_M_S: Final = 0.5
ALT_ACCEPTANCE_M: Final = 3.0
MIN_DIST_FOR_YAW_M: Final = 1.0
FILTER_OMEGA: Final = 1.0
FILTER_ZETA: Final = 0.7071
COURSE_DEADZONE_M_S: Final = 1.0
ORBIT_JERK: Final = 4.0
ORBIT_ACC: Final = 2.0
DIST_ADJUST_M_S, DIST_MAX_M = 2.0, 100.0
HEIGHT_ADJUST_M_S, HEIGHT_MAX_M = 1.5, 100.0
ANGLE_ADJUST_RAD_S: Final = 1.5
ADJUST_WINDOW_S: Final = 0.5


@dataclass(frozen=True, slots=True)
class FollowSettings:
    height: float
    distance: float
    angle_rad: float
    alt_mode: int
    max_vel: float
    responsiveness: float
    deadzone: float

    @classmethod
    def from_params(cls, p: ParamRegistry) -> FollowSettings:
        return cls(float(p["FLW_TGT_HT"]), float(p["FLW_TGT_DST"]), wrap_pi(math.radians(float(p["FLW_TGT_FA"]))),
                   int(p["FLW_TGT_ALT_M"]), float(p["FLW_TGT_MAX_VEL"]), float(p["FLW_TGT_RS"]),
                   float(p["MAN_DEADZONE"]))


class ReferenceModel:
    """SecondOrderReferenceModel on a 3-vector: position and rate pulled towards the samples."""

    def __init__(self) -> None:
        self.x: Vec3 = NAN3
        self.v: Vec3 = NAN3

    def reset(self, x: Vec3, v: Vec3) -> None:
        self.x, self.v = x, v

    def update(self, dt: float, x_s: Vec3, v_s: Vec3) -> None:
        w2, c = FILTER_OMEGA * FILTER_OMEGA, 2.0 * FILTER_ZETA * FILTER_OMEGA
        acc = [w2 * (x_s[i] - self.x[i]) + c * (v_s[i] - self.v[i]) for i in range(3)]
        v = [self.v[i] + acc[i] * dt for i in range(3)]
        self.x = (self.x[0] + v[0] * dt, self.x[1] + v[1] * dt, self.x[2] + v[2] * dt)
        self.v = (v[0], v[1], v[2])


class FollowTargetTask:
    """One activation of FlightTaskAutoFollowTarget."""

    period_us = TASK_PERIOD_US
    finished = False
    want_takeoff = False
    setpoint_type = SetpointType.POSITION

    def __init__(self, nav: NavInput, params: ParamRegistry) -> None:
        self._params, self._version = params, params.version
        self.s = FollowSettings.from_params(params)
        self.sticks: ManualControlSetpoint = CENTRED
        self.fix: TargetFix | None = None  # the latest FOLLOW_TARGET (the executor keeps it current)
        self.estimator = TargetEstimator(self.s.responsiveness)
        self.target = ReferenceModel()
        self.distance, self.height, self.angle = self.s.distance, self.s.height, self.s.angle_rad
        self._course = 0.0  # initialised north
        self._orbit = AxisSmoother(0.0, 0.0, 0.0)  # the orbit angle around the target (rad), from north
        self._home_z = nav.home_ned_m[2]
        self._pos: Vec3 = nav.pos_ned_m
        self._vel: Vec3 = NAN3
        self._acc: Vec3 = NAN3
        self._yaw = nav.yaw_rad
        self.last_estimate: TargetEstimate | None = None

    def update(self, nav: NavInput, dt_s: float) -> TrajectorySetpoint:
        if self._params.version != self._version:
            self._new_params()
        est = self.last_estimate = self.estimator.update(nav.time_us, self.fix)
        if est is not None and est.valid:
            self._follow(nav, est, dt_s)
        else:  # no valid estimate: stay
            self._pos, self._vel = NAN3, (0.0, 0.0, 0.0)
        return TrajectorySetpoint(self._pos, self._vel, self._acc, self._yaw, NAN)

    def _new_params(self) -> None:
        """updateParams: a changed FLW_TGT_DST / HT / FA replaces the (stick-adjusted) value."""
        old, self.s = self.s, FollowSettings.from_params(self._params)
        self._version = self._params.version
        if self.s.distance != old.distance:
            self.distance = self.s.distance
        if self.s.height != old.height:
            self.height = self.s.height
        if self.s.angle_rad != old.angle_rad:
            self.angle = self.s.angle_rad

    def _follow(self, nav: NavInput, est: TargetEstimate, dt_s: float) -> None:
        tgt = self.target
        if not (_finite(tgt.x) and _finite(tgt.v)):
            tgt.reset(est.pos_ned_m, est.vel_ned_m_s)
        else:
            tgt.update(dt_s, est.pos_ned_m, est.vel_ned_m_s)
        p = nav.pos_ned_m
        dx, dy = tgt.x[0] - p[0], tgt.x[1] - p[1]
        heading = math.atan2(dy, dx)
        self._adjust_by_sticks(nav, math.hypot(dx, dy), wrap_pi(heading + math.pi), dt_s)
        self._course = self._target_course(tgt.v, est.vel_ned_m_s)
        a = self._orbit_angle(dt_s)
        desired = self._desired_position(tgt.x, a)
        if abs(desired[2] - p[2]) < ALT_ACCEPTANCE_M:
            rate, d = self._orbit.v, self.distance
            vt = (-math.sin(a) * rate * d, math.cos(a) * rate * d)
            radial = (vt[0] * vt[0] + vt[1] * vt[1]) / d
            tang = self._orbit.a * d
            self._pos = desired
            self._vel = (vt[0] + tgt.v[0], vt[1] + tgt.v[1], self._vel[2])
            self._acc = (-radial * math.cos(a) - tang * math.sin(a), -radial * math.sin(a) + tang * math.cos(a),
                         self._acc[2])
        else:
            self._pos = (p[0], p[1], desired[2])
        if math.hypot(dx, dy) > MIN_DIST_FOR_YAW_M:
            self._yaw = heading
        if -(p[2] - self._home_z) < MIN_SAFETY_ALT_M:  # emergency ascent (distance to the ground from home)
            self._pos, self._vel = (NAN, NAN, p[2]), (0.0, 0.0, -EMERGENCY_ASCENT_M_S)

    def _adjust_by_sticks(self, nav: NavInput, dist: float, measured_angle: float, dt_s: float) -> None:
        st, dz = self.sticks, self.s.deadzone
        if abs(self._pos[2] - nav.pos_ned_m[2]) < HEIGHT_ADJUST_M_S * ADJUST_WINDOW_S:
            h = self.height + HEIGHT_ADJUST_M_S * stick_expo(st.throttle, dz) * dt_s
            self.height = constrain(h, MIN_SAFETY_ALT_M, HEIGHT_MAX_M)
        if abs(dist - self.distance) < DIST_ADJUST_M_S * ADJUST_WINDOW_S:
            d = self.distance + DIST_ADJUST_M_S * stick_expo(st.pitch, dz) * dt_s
            self.distance = constrain(d, MIN_DIST_FOR_YAW_M, DIST_MAX_M)
        if abs(wrap_pi(measured_angle - self._orbit.x)) < ANGLE_ADJUST_RAD_S * ADJUST_WINDOW_S:
            speed = min(ANGLE_ADJUST_RAD_S, self.s.max_vel / self.distance)
            self.angle = wrap_pi(self.angle + speed * stick_expo(st.roll, dz) * dt_s)

    def _target_course(self, vel_filtered: Vec3, vel_raw: Vec3) -> float:
        """updateTargetOrientation: the course only while both velocities are at least 1 m/s."""
        if (math.hypot(vel_filtered[0], vel_filtered[1]) >= COURSE_DEADZONE_M_S
                and math.hypot(vel_raw[0], vel_raw[1]) >= COURSE_DEADZONE_M_S):
            return math.atan2(vel_filtered[1], vel_filtered[0])
        return self._course

    def _orbit_angle(self, dt_s: float) -> float:
        """updateOrbitAngleTrajectory: a jerk-limited angle towards course + follow angle (unwrapped)."""
        traj, d = self._orbit, self.distance
        goal = traj.x + wrap_pi(self._course + self.angle - traj.x)
        traj.max_jerk, traj.max_accel, traj.max_vel = ORBIT_JERK / d, ORBIT_ACC / d, self.s.max_vel / d
        remaining = goal - traj.x
        rate = max_speed_from_distance(traj.max_jerk, traj.max_accel, abs(remaining), 0.0)
        traj.update_durations(math.copysign(rate, remaining) if remaining else 0.0)
        traj.update_traj(dt_s)
        return traj.x

    def _desired_position(self, target: Vec3, angle: float) -> Vec3:
        x, y = target[0] + math.cos(angle) * self.distance, target[1] + math.sin(angle) * self.distance
        mode = self.s.alt_mode
        if mode == 2:
            return x, y, target[2] - self.height
        # 0: above home; 1: above the ground, which is flat at home's height here (no terrain in SIH)
        return x, y, self._home_z - self.height

    def drain_messages(self) -> list[tuple[Severity, str]]:
        return []


def _finite(v: Vec3) -> bool:
    return isfinite(v[0]) and isfinite(v[1]) and isfinite(v[2])
