"""The heading of the auto modes, smoothed as PX4's `src/lib/motion_planning/HeadingSmoothing.cpp` does.

PX4 reuses its one-axis jerk-limited velocity planner (VelocitySmoothing, here `smoothing.AxisSmoother`) one
derivative down: the planner's "velocity" is the heading, its "acceleration" the heading rate (limit
MPC_YAWRAUTO_MAX) and its "jerk" the heading acceleration (limit MPC_YAWRAUTO_ACC); its velocity limit is 2 pi,
enough for the wrap handling. Each update takes the short way round to the target (the target is unwrapped next to
the current heading), replans, advances one step and wraps the heading back to [-pi, pi).

FlightTaskAuto::_smoothYaw (`src/modules/flight_mode_manager/tasks/Auto/FlightTaskAuto.cpp`) feeds it every cycle
and counts the heading setpoint as aligned when the smoothed heading is within MIS_YAW_ERR of the target and the
heading rate is below MPC_YAWRAUTO_MAX (not saturated).
"""

from __future__ import annotations

import math
from typing import Final

from sitl_emu.control.qmath import isfinite
from sitl_emu.motion_planning.smoothing import AxisSmoother

_TWO_PI: Final = 2.0 * math.pi


def wrap_pi(angle: float) -> float:
    return (angle + math.pi) % _TWO_PI - math.pi


class HeadingSmoother:
    """A heading setpoint limited in rate and acceleration (HeadingSmoothing)."""

    __slots__ = ("_axis",)

    def __init__(self, heading_rad: float, rate_rad_s: float = 0.0) -> None:
        self._axis = AxisSmoother()
        self._axis.max_vel = _TWO_PI
        self.reset(heading_rad, rate_rad_s)

    def set_limits(self, max_rate_rad_s: float, max_accel_rad_s2: float) -> None:
        self._axis.max_accel = max_rate_rad_s
        self._axis.max_jerk = max_accel_rad_s2

    def reset(self, heading_rad: float, rate_rad_s: float = math.nan) -> None:
        """Restart from `heading_rad`; the rate is kept when `rate_rad_s` is NaN (HeadingSmoothing::reset)."""
        axis = self._axis
        rate = rate_rad_s if isfinite(rate_rad_s) else axis.a
        axis.reset(rate, wrap_pi(heading_rad), axis.x)

    def update(self, target_rad: float, dt_s: float) -> None:
        axis = self._axis
        axis.update_durations(axis.v + wrap_pi(target_rad - axis.v))  # the short way round
        axis.update_traj(dt_s)
        axis.v = wrap_pi(axis.v)

    @property
    def heading_rad(self) -> float:
        return self._axis.v

    @property
    def rate_rad_s(self) -> float:
        return self._axis.a
