"""AUTO.RTL for a multicopter returning to home (PX4 navigator rtl.cpp + rtl_direct.cpp, RTL_TYPE 0).

States as RtlDirect: CLIMBING (to the return altitude above the current position) -> AVOID_GEOFENCE (the waypoints of
the geofence avoidance planner, navigator/geofence_avoidance.py, if the straight way crosses the fence: each at the
return altitude, facing it from where the vehicle was when it became current, the next one or home as the triplet's
next) -> MOVE_TO_LOITER (home at the return altitude) -> LAND when RTL_LAND_DELAY is 0 (the MC default); otherwise
LOITER_DOWN (to RTL_DESCEND_ALT) -> LOITER_HOLD (RTL_LAND_DELAY seconds, forever if < 0) -> MOVE_TO_LAND_HOVER ->
LAND. The destination is home or the rally point RTL_TYPE selects (navigator/rally.py; "home" below means that
destination). The return altitude follows RTL::calculate_return_alt_from_cone_half_angle (RTL_RETURN_ALT,
RTL_CONE_ANG, RTL_MIN_DIST, NAV_ACC_RAD).
"""

from __future__ import annotations

import math
import struct
from collections.abc import Sequence
from enum import Enum
from typing import Final

from sitl_emu.flight_tasks.core import AutoSettings, Task, Waypoint
from sitl_emu.navigator.setpoint import NavInput, SetpointType
from sitl_emu.params import ParamRegistry
from sitl_emu.px4 import Severity
from sitl_emu.types import NAN, Vec3

_F32: Final = struct.Struct("<f")


class RtlState(Enum):
    """RtlDirect's states (rtl_direct.h RTLState), named for what the vehicle does."""

    CLIMB = "climb"  # CLIMBING
    AVOID = "avoid"  # AVOID_GEOFENCE
    RETURN = "return"  # MOVE_TO_LOITER
    DESCEND = "descend"  # LOITER_DOWN
    HOLD = "hold"  # LOITER_HOLD
    HOVER = "hover"  # MOVE_TO_LAND_HOVER
    LAND = "land"  # LAND
    IDLE = "idle"  # IDLE (on the ground)


def rtl_start_text(return_alt_amsl_m: float, destination_alt_amsl_m: float) -> str:
    """The text RtlDirect::on_activation logs (navigator/rtl_direct.cpp): both altitudes are floats (32 bit) in PX4,
    rounded up, the second being the float difference; so 518.0000001 m, which is 518.0 as a float, says 518."""
    rtl_alt = _f32(return_alt_amsl_m)
    above = _f32(rtl_alt - _f32(destination_alt_amsl_m))
    return f"RTL: start return at {math.ceil(rtl_alt):d} m ({math.ceil(above):d} m above destination)"


def _f32(x: float) -> float:
    """x rounded to the nearest 32-bit float, as PX4 holds it."""
    return float(_F32.unpack(_F32.pack(x))[0]) if math.isfinite(x) else x


def return_altitude_up(s: AutoSettings, destination_ned_m: Vec3, pos_ned_m: Vec3) -> float:
    """RTL::computeReturnAltitude: the return altitude (up, local frame) above `destination_ned_m` after the cone
    rule, never below the current altitude."""
    home_up, current_up = -destination_ned_m[2], -pos_ned_m[2]
    dist = math.hypot(destination_ned_m[0] - pos_ned_m[0], destination_ned_m[1] - pos_ned_m[1])
    if s.rtl_cone_ang <= 0:
        return max(current_up, home_up + s.rtl_return_alt)
    alt = home_up + s.rtl_return_alt
    if dist <= s.nav_acc_rad:
        alt = home_up + 2.0 * dist
    else:
        if dist <= s.rtl_min_dist:
            half_angle = math.radians(min(max(s.rtl_cone_ang, 1.0), 89.0))
            alt = min(dist / math.tan(half_angle) + home_up, alt)
        alt = max(alt, home_up + 2.0 * s.nav_acc_rad)
    return max(alt, current_up)


class RtlTask(Task):
    def __init__(self, nav: NavInput, params: ParamRegistry, destination: tuple[Vec3, float] | None = None,
                 loiter_at_ned_m: Vec3 | None = None, avoid_path: Sequence[tuple[float, float]] = ()) -> None:
        """`destination`: where to return (rtl.cpp findRtlDestination: home, or a rally point chosen by
        navigator/rally.py), NED position and yaw. `loiter_at_ned_m`: the loiter the vehicle was established on when RTL
        began (a finished mission's last setpoint): the climb keeps its centre (rtl_direct.cpp CLIMBING,
        is_established_on_loiter); else the climb is centred where the vehicle is. `avoid_path`: the geofence
        avoidance waypoints (north, east) to fly before home, none when the straight way is clear."""
        super().__init__(nav, params)
        self._loiter_at = loiter_at_ned_m
        self._yaw_err_rad = math.radians(float(params.get("MIS_YAW_ERR")) if "MIS_YAW_ERR" in params else 12.0)
        self._home: Vec3 = nav.home_ned_m if destination is None else destination[0]
        self._home_yaw = nav.home_yaw_rad if destination is None else destination[1]
        self._rtl_up_m = self._return_altitude_up(nav)
        self._state = RtlState.IDLE
        self._hold_until_us = 0
        self._avoid = list(avoid_path)
        self._cursor = 0  # the avoidance waypoint flown (GeofenceAvoidancePlanner's path cursor)
        self._avoid_yaw = NAN
        if nav.landed:
            self._enter(RtlState.IDLE, nav)
        else:
            self._enter(RtlState.CLIMB if -nav.pos_ned_m[2] < self._rtl_up_m else self._after_climb(), nav)
        self._say(Severity.INFO, rtl_start_text(nav.ref_alt_amsl_m + self._rtl_up_m,
                                                nav.ref_alt_amsl_m - self._home[2]))
        if self._avoid:
            self._say(Severity.INFO, "RTL: avoiding geofence")

    @property
    def state(self) -> RtlState:
        return self._state

    @property
    def return_alt_up_m(self) -> float:
        return self._rtl_up_m

    def _return_altitude_up(self, nav: NavInput) -> float:
        return return_altitude_up(self._settings, self._home, nav.pos_ned_m)

    def _dist_xy(self, nav: NavInput) -> float:
        return math.hypot(self._home[0] - nav.pos_ned_m[0], self._home[1] - nav.pos_ned_m[1])

    def _after_climb(self) -> RtlState:
        """_updateRtlState after CLIMBING or an AVOID_GEOFENCE waypoint: the next avoidance waypoint, else home."""
        return RtlState.AVOID if self._cursor < len(self._avoid) else RtlState.RETURN

    def _enter(self, state: RtlState, nav: NavInput) -> None:
        self._state = state
        s = self._settings
        if state is RtlState.CLIMB:
            at = self._loiter_at if self._loiter_at is not None else nav.pos_ned_m
            self._climb_xy = (at[0], at[1])
            self._climb_yaw = nav.yaw_rad
        elif state is RtlState.AVOID:  # facing the waypoint from here (MPC_YAW_MODE weathervane off)
            px, py = self._avoid[self._cursor]
            self._avoid_yaw = math.atan2(py - nav.pos_ned_m[1], px - nav.pos_ned_m[0])
        elif state is RtlState.RETURN:
            self._return_yaw = self._home_yaw if self._dist_xy(nav) < s.rtl_min_dist else NAN
        elif state is RtlState.HOLD:
            self._hold_until_us = nav.time_us + int(s.rtl_land_delay * 1e6)
            if s.rtl_land_delay < 0.0:
                self._say(Severity.INFO, "RTL: completed, loitering")
        elif state is RtlState.LAND:
            self._say(Severity.INFO, "RTL: land at destination")

    def _heading_reached(self, nav: NavInput, yaw_rad: float) -> bool:
        """mission_block.cpp: an item with a heading (the return leg near home faces home's heading) is reached only
        once the heading is within MIS_YAW_ERR (MIS_YAW_TMT -1: no timeout)."""
        if not math.isfinite(yaw_rad):
            return True
        err = (yaw_rad - nav.yaw_rad + math.pi) % math.tau - math.pi
        return abs(err) < self._yaw_err_rad

    def _loiter_up_m(self) -> float:
        return min(-self._home[2] + self._settings.rtl_descend_alt, self._rtl_up_m)

    def _waypoint(self, nav: NavInput) -> Waypoint:
        self._advance(nav)
        return self._current_waypoint()

    def _current_waypoint(self) -> Waypoint:
        hx, hy = self._home[0], self._home[1]
        st = self._state
        if st is RtlState.CLIMB:
            return Waypoint(SetpointType.POSITION, (self._climb_xy[0], self._climb_xy[1], -self._rtl_up_m),
                            self._climb_yaw)
        if st is RtlState.AVOID:
            return self._avoid_waypoint()
        if st is RtlState.RETURN:
            return Waypoint(SetpointType.POSITION, (hx, hy, -self._rtl_up_m), self._return_yaw)
        if st in (RtlState.DESCEND, RtlState.HOLD, RtlState.HOVER):
            return Waypoint(SetpointType.POSITION, (hx, hy, -self._loiter_up_m()), self._home_yaw)
        if st is RtlState.LAND:
            return Waypoint(SetpointType.LAND, (hx, hy, NAN), self._home_yaw)
        return Waypoint(SetpointType.IDLE, self._home)

    def _avoid_waypoint(self) -> Waypoint:
        """An AVOID_GEOFENCE item: the line from the previous avoidance waypoint (none to the first one), the next
        one or home as the triplet's next."""
        z = -self._rtl_up_m
        x, y = self._avoid[self._cursor]
        previous = (*self._avoid[self._cursor - 1], z) if self._cursor > 0 else None
        nxt = self._avoid[self._cursor + 1] if self._cursor + 1 < len(self._avoid) else (self._home[0], self._home[1])
        return Waypoint(SetpointType.POSITION, (x, y, z), self._avoid_yaw, NAN, previous, (nxt[0], nxt[1], z))

    def _reached_xyz(self, nav: NavInput, x: float, y: float, up: float) -> bool:
        s = self._settings
        return math.hypot(x - nav.pos_ned_m[0], y - nav.pos_ned_m[1]) <= s.nav_acc_rad \
            and abs(-nav.pos_ned_m[2] - up) <= s.nav_mc_alt_rad

    def _advance(self, nav: NavInput) -> None:
        """RtlDirect::_updateRtlState once the current item is reached (mission_block acceptance rules)."""
        s = self._settings
        up = -nav.pos_ned_m[2]
        near_xy = self._dist_xy(nav) <= s.nav_acc_rad
        st = self._state
        if st is RtlState.CLIMB and up >= self._rtl_up_m - s.nav_mc_alt_rad:
            self._enter(self._after_climb(), nav)
        elif st is RtlState.AVOID and self._reached_xyz(nav, *self._avoid[self._cursor], self._rtl_up_m) \
                and self._heading_reached(nav, self._avoid_yaw):
            self._cursor += 1
            self._enter(self._after_climb(), nav)
        elif st is RtlState.RETURN and near_xy and abs(up - self._rtl_up_m) <= s.nav_mc_alt_rad \
                and self._heading_reached(nav, self._return_yaw):
            self._enter(RtlState.LAND if s.rtl_land_delay == 0.0 else RtlState.DESCEND, nav)
        elif st is RtlState.DESCEND and abs(up - self._loiter_up_m()) <= s.nav_mc_alt_rad:
            self._enter(RtlState.HOLD, nav)
        elif st is RtlState.HOLD and s.rtl_land_delay >= 0.0 and nav.time_us >= self._hold_until_us:
            self._enter(RtlState.HOVER, nav)
        elif st is RtlState.HOVER and near_xy:
            self._enter(RtlState.LAND, nav)
