"""Navigator tasks: what each auto mode flies (takeoff, hold, land, return, reposition).

Each factory returns a `Task` for one activation of a mode; the commander calls `task.update(nav, dt_s)` every
cycle and hands the `TrajectorySetpoint` to the controller. Behaviour after PX4's navigator
(`src/modules/navigator/{takeoff,loiter,land,rtl,rtl_direct}.cpp`) and FlightTaskAuto (see `core`).
"""

from __future__ import annotations

from collections.abc import Sequence

from sitl_emu.control.qmath import hypot, isfinite
from sitl_emu.flight_tasks.core import AutoSettings, Task, Waypoint
from sitl_emu.flight_tasks.rtl import RtlTask
from sitl_emu.motion_planning.smoothing import braking_distance
from sitl_emu.navigator.setpoint import NavInput, SetpointType
from sitl_emu.params import ParamRegistry
from sitl_emu.px4 import Severity
from sitl_emu.types import NAN, Vec3

__all__ = ["NavInput", "SetpointType", "Task", "make_land", "make_loiter", "make_reposition", "make_rtl",
           "make_takeoff"]


class TakeoffTask(Task):
    """AUTO.TAKEOFF (navigator takeoff.cpp): climb straight up to the target, then loiter there."""

    def __init__(self, nav: NavInput, params: ParamRegistry, target_alt_up_m: float | None) -> None:
        super().__init__(nav, params)
        current_up = -nav.pos_ned_m[2]
        if target_alt_up_m is None or not isfinite(target_alt_up_m):
            target_alt_up_m = current_up + self._settings.takeoff_alt
            self._say(Severity.INFO, f"Using default takeoff altitude: {self._settings.takeoff_alt:.1f} m")
        if target_alt_up_m < current_up:
            target_alt_up_m = current_up
            self._say(Severity.CRITICAL, "Already higher than takeoff altitude")
        self._target: Vec3 = (nav.pos_ned_m[0], nav.pos_ned_m[1], -target_alt_up_m)
        # mission_block.cpp: reached when within the altitude acceptance radius (half the climb if that is smaller)
        self._alt_acceptance_m = min(self._settings.nav_mc_alt_rad, 0.5 * (target_alt_up_m - current_up))
        self._finished = False
        # the three waypoints this task can give (frozen, so built once)
        self._wp_climb = Waypoint(SetpointType.TAKEOFF, self._target)
        self._wp_idle = Waypoint(SetpointType.IDLE, self._target)
        self._wp_hold = Waypoint(SetpointType.POSITION, self._target)

    @property
    def target_ned_m(self) -> Vec3:
        """Where the takeoff ends (Hold keeps this point)."""
        return self._target

    @property
    def finished(self) -> bool:
        return self._finished

    def _waypoint(self, nav: NavInput) -> Waypoint:
        if not self._finished and -nav.pos_ned_m[2] >= -self._target[2] - self._alt_acceptance_m:
            self._finished = True  # navigator turns the takeoff item into a loiter at the target
        if not self._finished:
            return self._wp_climb
        return self._wp_idle if nav.landed else self._wp_hold


class LoiterTask(Task):
    """AUTO.LOITER (Hold, loiter.cpp): idle on the ground, else hold the braking point (or the given point)."""

    def __init__(self, nav: NavInput, params: ParamRegistry, hold_at: Vec3 | None, yaw_rad: float | None) -> None:
        super().__init__(nav, params)
        self._yaw = yaw_rad if yaw_rad is not None and isfinite(yaw_rad) else nav.yaw_rad
        if hold_at is not None:
            self._target = _fill_nan(hold_at, nav.pos_ned_m)
            near = abs(self._target[2] - nav.pos_ned_m[2]) <= self._settings.nav_mc_alt_rad
            self._idle = (nav.landed and near) or not nav.armed
        else:
            self._target = braking_point(nav, self._settings)
            self._idle = nav.landed or not nav.armed
        if self._idle:
            self._wp = Waypoint(SetpointType.IDLE, self._target)
        else:
            self._wp = Waypoint(SetpointType.POSITION, self._target, self._yaw)

    @property
    def target_ned_m(self) -> Vec3:
        return self._target

    def _waypoint(self, nav: NavInput) -> Waypoint:
        return self._wp


class LandTask(Task):
    """AUTO.LAND (land.cpp): descend at the braking stop point with PX4's land speed profile."""

    def __init__(self, nav: NavInput, params: ParamRegistry) -> None:
        super().__init__(nav, params)
        self._target = braking_point(nav, self._settings)
        self._wp = Waypoint(SetpointType.LAND, self._target)

    def _waypoint(self, nav: NavInput) -> Waypoint:
        return self._wp


class RepositionTask(Task):
    """DO_REPOSITION in Hold (navigator_main.cpp reposition triplet): fly to the point at the given speed."""

    def __init__(self, nav: NavInput, params: ParamRegistry, target_ned_m: Vec3, yaw_rad: float,
                 speed_m_s: float) -> None:
        super().__init__(nav, params)
        self._target = _fill_nan(target_ned_m, nav.pos_ned_m)
        self._yaw = yaw_rad
        self._speed = speed_m_s if isfinite(speed_m_s) and speed_m_s > 0.0 else NAN
        self._wp = Waypoint(SetpointType.POSITION, self._target, self._yaw, self._speed)

    @property
    def target_ned_m(self) -> Vec3:
        return self._target

    def _waypoint(self, nav: NavInput) -> Waypoint:
        return self._wp


def braking_point(nav: NavInput, settings: AutoSettings) -> Vec3:
    """Navigator::calculate_breaking_stop: where the vehicle stops horizontally, at the current altitude."""
    vx, vy = nav.vel_ned_m_s[0], nav.vel_ned_m_s[1]
    speed = hypot(vx, vy)
    if speed < 1e-6:
        return nav.pos_ned_m
    dist = braking_distance(speed, settings.jerk, settings.acc_hor, 0.6 * settings.jerk)
    return (nav.pos_ned_m[0] + vx / speed * dist, nav.pos_ned_m[1] + vy / speed * dist, nav.pos_ned_m[2])


def _fill_nan(target: Vec3, fallback: Vec3) -> Vec3:
    return (
        target[0] if isfinite(target[0]) else fallback[0],
        target[1] if isfinite(target[1]) else fallback[1],
        target[2] if isfinite(target[2]) else fallback[2],
    )


def make_takeoff(nav: NavInput, params: ParamRegistry, target_alt_up_m: float | None) -> Task:
    """Takeoff to `target_alt_up_m` above the local origin (None: current height + MIS_TAKEOFF_ALT)."""
    return TakeoffTask(nav, params, target_alt_up_m)


def make_loiter(nav: NavInput, params: ParamRegistry, hold_at_ned_m: Vec3 | None = None,
                yaw_rad: float | None = None) -> Task:
    """Hold: idle on the ground, braking point in the air, or `hold_at_ned_m` (after takeoff / reposition)."""
    return LoiterTask(nav, params, hold_at_ned_m, yaw_rad)


def make_land(nav: NavInput, params: ParamRegistry) -> Task:
    """Land at the braking stop point; keeps pushing down on the ground until the land detector disarms."""
    return LandTask(nav, params)


def make_rtl(nav: NavInput, params: ParamRegistry, destination: tuple[Vec3, float] | None = None,
             loiter_at_ned_m: Vec3 | None = None, avoid_path: Sequence[tuple[float, float]] = ()) -> Task:
    """Return: climb to the return altitude, fly home (or to `destination`: NED position and yaw, a rally point
    navigator/rally.py chose) at MPC_XY_CRUISE, land (RTL_LAND_DELAY: wait first); `loiter_at_ned_m`: climb there (the
    loiter a finished mission left); `avoid_path`: the geofence avoidance waypoints (north, east) flown before home."""
    return RtlTask(nav, params, destination, loiter_at_ned_m, avoid_path)


def make_reposition(nav: NavInput, params: ParamRegistry, target_ned_m: Vec3, yaw_rad: float,
                    speed_m_s: float) -> Task:
    """Go to `target_ned_m` (NaN components: keep current), heading `yaw_rad` (NaN: face the target)."""
    return RepositionTask(nav, params, target_ned_m, yaw_rad, speed_m_s)
