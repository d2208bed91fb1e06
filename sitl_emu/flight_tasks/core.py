"""The shared machinery of the flight tasks: settings, the base Task and PX4's FlightTaskAuto core (their input,
NavInput, and the setpoint types are the navigator's: navigator/setpoint.py).

`AutoCore` turns a waypoint (type + target + yaw) into a smoothed trajectory setpoint the way PX4's
`src/modules/flight_mode_manager/tasks/Auto/FlightTaskAuto.cpp` does: per-cycle trajectory constraints
(_updateTrajConstraints: takeoff speed/acceleration near the ground, MPC_ACC_UP_MAX/MPC_Z_V_AUTO_UP upwards,
MPC_ACC_DOWN_MAX/MPC_Z_V_AUTO_DN downwards, and how far the trajectory may run ahead of a lagging vehicle before
its time stops: MPC_XY_ERR_MAX horizontally, MPC_Z_ERR_MAX vertically), the land speed profile
(_prepareLandSetpoints), the idle setpoint, heading towards the waypoint (MPC_YAW_MODE 0) and its smoothing
(_smoothYaw: heading.py, MPC_YAWRAUTO_MAX and MPC_YAWRAUTO_ACC).
It also reproduces FlightModeManager's reset of the trajectory while the takeoff ramp has not started
(`src/modules/flight_mode_manager/FlightModeManager.cpp` generateTrajectorySetpoint -> FlightTaskAuto::reActivate).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Final

from sitl_emu.control.qmath import atan2, hypot, isfinite
from sitl_emu.control.takeoff import before_ramp
from sitl_emu.motion_planning.heading import HeadingSmoother, wrap_pi
from sitl_emu.motion_planning.smoothing import PositionSmoother
from sitl_emu.navigator.setpoint import NavInput, SetpointType
from sitl_emu.params import ParamRegistry
from sitl_emu.px4 import Severity
from sitl_emu.types import NAN, TrajectorySetpoint, Vec3

WANT_TAKEOFF_VZ_M_S: Final = -0.3  # FlightTaskAuto: _want_takeoff = unsmoothed vz < -0.3
YAW_FIRST: Final = 4  # MPC_YAW_MODE towards_waypoint_yaw_first
REACTIVATE_VZ_M_S: Final = 0.7  # FlightTaskAuto::reActivate resets the trajectory velocity to 0.7 m/s down
IDLE_ACC_Z_M_S2: Final = 100.0  # FlightTaskAuto idle: "high downwards acceleration to make sure there's no thrust"
_IDLE_SETPOINT: Final = TrajectorySetpoint(acceleration_ned_m_s2=(0.0, 0.0, IDLE_ACC_Z_M_S2), yaw_rad=NAN)


@dataclass(frozen=True, slots=True)
class AutoSettings:
    """Every parameter the tasks read, fetched by name from the registry (PX4 defaults if a name is missing)."""

    jerk: float
    acc_hor: float
    acc_up: float
    acc_down: float
    xy_vel_max: float
    z_v_auto_up: float
    z_v_auto_dn: float
    z_vel_max_dn: float
    tko_speed: float
    tko_ramp_t: float
    land_speed: float
    land_crawl: float
    land_alt1: float
    land_alt2: float
    land_alt3: float
    xy_cruise: float
    xy_err_max: float
    z_err_max: float
    yawrate_max_rad_s: float
    yawacc_max_rad_s2: float
    yaw_err_rad: float
    yaw_mode: int
    nav_acc_rad: float
    nav_mc_alt_rad: float
    takeoff_alt: float
    rtl_return_alt: float
    rtl_descend_alt: float
    rtl_land_delay: float
    rtl_min_dist: float
    rtl_cone_ang: float
    xy_traj_p: float

    @classmethod
    def from_params(cls, params: ParamRegistry) -> AutoSettings:
        values: dict[str, Any] = {f: _get(params, name, default) for f, (name, default) in _PARAM_NAMES.items()}
        for name in ("yawrate_max_rad_s", "yawacc_max_rad_s2", "yaw_err_rad"):
            values[name] = math.radians(values[name])
        values["yaw_mode"] = int(values["yaw_mode"])
        return cls(**values)


_PARAM_NAMES: Final[dict[str, tuple[str, float]]] = {
    "jerk": ("MPC_JERK_AUTO", 4.0), "acc_hor": ("MPC_ACC_HOR", 3.0), "acc_up": ("MPC_ACC_UP_MAX", 4.0),
    "acc_down": ("MPC_ACC_DOWN_MAX", 3.0), "xy_vel_max": ("MPC_XY_VEL_MAX", 12.0),
    "z_v_auto_up": ("MPC_Z_V_AUTO_UP", 3.0), "z_v_auto_dn": ("MPC_Z_V_AUTO_DN", 1.5),
    "z_vel_max_dn": ("MPC_Z_VEL_MAX_DN", 1.5), "tko_speed": ("MPC_TKO_SPEED", 1.5),
    "tko_ramp_t": ("MPC_TKO_RAMP_T", 3.0), "land_speed": ("MPC_LAND_SPEED", 0.7),
    "land_crawl": ("MPC_LAND_CRWL", 0.3), "land_alt1": ("MPC_LAND_ALT1", 10.0), "land_alt2": ("MPC_LAND_ALT2", 5.0),
    "land_alt3": ("MPC_LAND_ALT3", 1.0), "xy_cruise": ("MPC_XY_CRUISE", 5.0), "xy_err_max": ("MPC_XY_ERR_MAX", 2.0),
    "z_err_max": ("MPC_Z_ERR_MAX", 1.0),
    "yawrate_max_rad_s": ("MPC_YAWRAUTO_MAX", 60.0), "yawacc_max_rad_s2": ("MPC_YAWRAUTO_ACC", 20.0),
    "yaw_err_rad": ("MIS_YAW_ERR", 12.0), "yaw_mode": ("MPC_YAW_MODE", 0),
    "nav_acc_rad": ("NAV_ACC_RAD", 10.0), "nav_mc_alt_rad": ("NAV_MC_ALT_RAD", 0.8),
    "takeoff_alt": ("MIS_TAKEOFF_ALT", 2.5), "rtl_return_alt": ("RTL_RETURN_ALT", 30.0),
    "rtl_descend_alt": ("RTL_DESCEND_ALT", 10.0), "rtl_land_delay": ("RTL_LAND_DELAY", 0.0),
    "rtl_min_dist": ("RTL_MIN_DIST", 10.0), "rtl_cone_ang": ("RTL_CONE_ANG", 45),
    "xy_traj_p": ("MPC_XY_TRAJ_P", 0.5),
}


def _get(params: ParamRegistry, name: str, default: float) -> float:
    return float(params.get(name)) if name in params else float(default)


@dataclass(frozen=True, slots=True)
class Waypoint:
    """One navigator position setpoint (kind IDLE, TAKEOFF, POSITION or LAND); NaN = not given.

    A mission leg also gives the triplet's previous and next waypoints (None: a single waypoint, as every other
    task flies) and the setpoint's acceptance radius (NaN: NAV_ACC_RAD)."""

    kind: SetpointType
    target_ned_m: Vec3
    yaw_rad: float = NAN
    cruise_m_s: float = NAN
    previous_ned_m: Vec3 | None = None
    next_ned_m: Vec3 | None = None
    acceptance_m: float = NAN


class AutoCore:
    """PX4's FlightTaskAuto for one activation: a smoothed trajectory towards the current waypoint."""

    def __init__(self, nav: NavInput, settings: AutoSettings) -> None:
        self.s = settings
        self.smoother = PositionSmoother((0.0, 0.0, 0.0), nav.vel_ned_m_s, nav.pos_ned_m)
        self._unsmoothed_vz = 0.0
        self._yaw_sp_prev = nav.yaw_rad
        self._yaw_lock: float | None = None
        self.heading = HeadingSmoother(nav.yaw_rad)  # FlightTaskAuto::activate: no previous setpoint here
        self.yaw_sp_aligned = False  # FlightTaskAuto's _yaw_sp_aligned
        self._kind_prev: SetpointType | None = None
        self._land_heading = NAN
        self.want_takeoff = False

    def carry_heading(self, previous: AutoCore) -> None:
        """Continue the previous auto mode's heading setpoint and rate (see Task.continue_heading)."""
        self.heading.reset(previous.heading.heading_rad, previous.heading.rate_rad_s)
        self._yaw_sp_prev = previous._yaw_sp_prev

    def step(self, nav: NavInput, dt_s: float, wp: Waypoint) -> TrajectorySetpoint:
        kind = wp.kind
        if kind is SetpointType.IDLE:
            return self._idle(nav)
        self._set_constraints(nav, wp)
        target, ff = wp.target_ned_m, (NAN, NAN, NAN)  # no feed-forward (written out: a module tuple is a dict look-up)
        if kind is SetpointType.LAND:
            target, ff = (target[0], target[1], NAN), (NAN, NAN, self._land_speed(nav))
        # MPC_YAW_MODE 4, yaw first: no motion while the heading is not aligned (FlightTaskAuto::_generateSetpoints
        # force_zero_velocity_setpoint)
        wait = self.s.yaw_mode == YAW_FIRST and not self.yaw_sp_aligned
        if wp.next_ned_m is not None and kind is SetpointType.POSITION:
            vz = self._unsmoothed_vz = self._path_step(nav, wp, dt_s, wait)
        else:
            vz = self._unsmoothed_vz = self.smoother.update(nav.pos_ned_m, target, ff, dt_s, wait)[2]
        self.want_takeoff = vz < WANT_TAKEOFF_VZ_M_S
        yaw, yawspeed = self._smooth_yaw(self._yaw_target(nav, wp), dt_s)
        self._kind_prev = kind
        ax, ay, az = self.smoother.axes
        out = TrajectorySetpoint((ax.x, ay.x, az.x), (ax.v, ay.v, az.v), (ax.a, ay.a, az.a), yaw, yawspeed)
        if before_ramp(nav.takeoff_state):  # FlightModeManager.cpp: takeoff_state < TAKEOFF_STATE_RAMPUP
            out = self._hold_before_ramp(nav, out)
        return out

    def _path_step(self, nav: NavInput, wp: Waypoint, dt_s: float, wait: bool) -> float:
        """A mission leg: previous -> target -> next (FlightTaskAuto passes the triplet to PositionSmoothing)."""
        sm, target = self.smoother, wp.target_ned_m
        sm.acceptance_xy_m = self._acceptance(wp)
        sm.acceptance_z_m = self.s.nav_mc_alt_rad
        sm.traj_gain = self.s.xy_traj_p
        previous = wp.previous_ned_m if wp.previous_ned_m is not None else target
        following = wp.next_ned_m if wp.next_ned_m is not None else target
        return sm.update_path(nav.pos_ned_m, previous, target, following, dt_s, wait)[2]

    def _acceptance(self, wp: Waypoint) -> float:
        return wp.acceptance_m if isfinite(wp.acceptance_m) else self.s.nav_acc_rad

    def _idle(self, nav: NavInput) -> TrajectorySetpoint:
        self.smoother.reset((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), nav.pos_ned_m)
        self._kind_prev, self.want_takeoff, self._yaw_sp_prev = SetpointType.IDLE, False, nav.yaw_rad
        self.heading.reset(nav.yaw_rad, 0.0)  # _smoothYaw without a heading setpoint
        self.yaw_sp_aligned = True
        return _IDLE_SETPOINT  # frozen: one shared instance

    def _hold_before_ramp(self, nav: NavInput, out: TrajectorySetpoint) -> TrajectorySetpoint:
        """FlightModeManager: before the takeoff ramp the task is re-activated every cycle (trajectory reset to the
        vehicle, 0.7 m/s down) after publishing. The upward intent reaches the controller only through
        `want_takeoff` (PX4's vehicle_constraints), which the caller must pass on."""
        self.smoother.reset((0.0, 0.0, 0.0), (0.0, 0.0, REACTIVATE_VZ_M_S), nav.pos_ned_m)
        return out

    def _set_constraints(self, nav: NavInput, wp: Waypoint) -> None:
        """FlightTaskAuto::_updateTrajConstraints."""
        s, sm = self.s, self.smoother
        cruise = wp.cruise_m_s if isfinite(wp.cruise_m_s) and wp.cruise_m_s > 0.0 else s.xy_cruise
        vel_max = s.xy_vel_max
        sm.cruise_speed_m_s = min(cruise, vel_max)
        sm.max_xy_error_m = s.xy_err_max
        sm.max_z_error_m = s.z_err_max  # the vertical time stretch: the altitude setpoint waits for a lagging vehicle
        if self._unsmoothed_vz < 0.0:  # going up
            acc_z, vel_z = s.acc_up, s.z_v_auto_up
            if wp.kind is SetpointType.TAKEOFF and self._dist_to_ground(nav) < s.land_alt1:
                ramp_acc = s.tko_speed / s.tko_ramp_t
                vel_z, acc_z = s.tko_speed, min(acc_z, ramp_acc)
                for axis in sm.axes[2:]:  # keep the altitude setpoint at the vehicle during the ramp
                    axis.set_position(nav.pos_ned_m[2])
        else:
            acc_z, vel_z = s.acc_down, s.z_v_auto_dn
        sm.set_limits(s.jerk, s.acc_hor, acc_z, s.xy_vel_max, vel_z)

    @staticmethod
    def _dist_to_ground(nav: NavInput) -> float:
        return max(-nav.pos_ned_m[2], 0.0)

    def _land_speed(self, nav: NavInput) -> float:
        """FlightTaskAuto::_prepareLandSetpoints: MPC_LAND_SPEED below ALT2, MPC_Z_VEL_MAX_DN above ALT1, linear in
        between; MPC_LAND_CRWL below ALT3 (SIH has a distance sensor, so the crawl applies)."""
        s, d = self.s, self._dist_to_ground(nav)
        alt1 = max(s.land_alt1, s.land_alt2)
        if d <= s.land_alt3:
            return s.land_crawl
        if d <= s.land_alt2:
            return s.land_speed
        if d >= alt1:
            return s.z_vel_max_dn
        return s.land_speed + (d - s.land_alt2) / (alt1 - s.land_alt2) * (s.z_vel_max_dn - s.land_speed)

    def _yaw_target(self, nav: NavInput, wp: Waypoint) -> float:
        if wp.kind is SetpointType.LAND:
            if self._kind_prev is not SetpointType.LAND or not isfinite(self._land_heading):
                self._land_heading = wp.yaw_rad if isfinite(wp.yaw_rad) else self._yaw_sp_prev
            return self._land_heading
        if isfinite(wp.yaw_rad):
            return wp.yaw_rad
        # MPC_YAW_MODE 0: face the waypoint while outside the acceptance radius, else keep the locked heading
        dx = wp.target_ned_m[0] - nav.pos_ned_m[0]
        dy = wp.target_ned_m[1] - nav.pos_ned_m[1]
        if self.s.yaw_mode in (0, 4) and isfinite(dx) and hypot(dx, dy) > self._acceptance(wp):
            self._yaw_lock = atan2(dy, dx)
        if self._yaw_lock is None:
            self._yaw_lock = nav.yaw_rad
        return self._yaw_lock

    def _smooth_yaw(self, yaw_sp: float, dt_s: float) -> tuple[float, float]:
        """FlightTaskAuto::_smoothYaw: the heading setpoint through HeadingSmoothing (rate and acceleration
        limited), aligned when within MIS_YAW_ERR of the target and not turning at the rate limit."""
        s, heading = self.s, self.heading
        heading.set_limits(s.yawrate_max_rad_s, s.yawacc_max_rad_s2)
        heading.update(yaw_sp, dt_s)
        yaw, rate = heading.heading_rad, heading.rate_rad_s
        self.yaw_sp_aligned = abs(wrap_pi(yaw_sp - yaw)) < s.yaw_err_rad and abs(rate) < s.yawrate_max_rad_s
        self._yaw_sp_prev = yaw
        return yaw, rate

class Task:
    """One activation of an auto mode. Subclasses implement `_waypoint(nav)`."""

    # flight_mode_manager runs the task on each estimator update; sitl_emu runs the auto tasks with the position
    # controller (125 Hz), the manual ones at FlightModeManager's 50 Hz (manual.py)
    period_us = 8000

    def __init__(self, nav: NavInput, params: ParamRegistry) -> None:
        self._params = params
        self._settings = AutoSettings.from_params(params)
        self._params_watch = params.changes.watch()  # params/changes.py
        self._core = AutoCore(nav, self._settings)
        self._messages: list[tuple[Severity, str]] = []
        self._type = SetpointType.POSITION

    def update(self, nav: NavInput, dt_s: float) -> TrajectorySetpoint:
        """The trajectory setpoint for this cycle (NaN = not controlled)."""
        if self._params_watch.changed():
            self._settings = AutoSettings.from_params(self._params)
            self._core.s = self._settings
        wp = self._waypoint(nav)
        self._type = wp.kind
        return self._core.step(nav, dt_s, wp)

    def _waypoint(self, nav: NavInput) -> Waypoint:
        raise NotImplementedError

    def continue_heading(self, previous: Task) -> None:
        """FlightModeManager::switchTask does not activate FlightTaskAuto again when one auto mode follows another
        (the same task), so the heading setpoint and its rate carry on instead of restarting at the vehicle's
        heading with no rate."""
        self._core.carry_heading(previous._core)

    @property
    def setpoint_type(self) -> SetpointType:
        """position_setpoint.type of the last update: IDLE, POSITION, TAKEOFF or LAND."""
        return self._type

    @property
    def finished(self) -> bool:
        return False

    @property
    def want_takeoff(self) -> bool:
        """PX4's vehicle_constraints.want_takeoff: the unsmoothed trajectory asks to climb (> 0.3 m/s)."""
        return self._core.want_takeoff

    def _say(self, severity: Severity, text: str) -> None:
        self._messages.append((severity, text))

    def drain_messages(self) -> list[tuple[Severity, str]]:
        """Navigator texts since the last call (PX4 also sends them as events; no trailing tab here)."""
        out, self._messages = self._messages, []
        return out
