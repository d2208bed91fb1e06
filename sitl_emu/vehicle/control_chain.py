"""The per-tick chain Vehicle.step drives below the commander: mode executor, control cascade, land detector.

`ControlChain` turns the vehicle's state into each component's input type, so vehicle.py stays a readable list of
steps. Rates follow PX4: the land detector runs at 50 Hz (LandDetector.h LAND_DETECTOR_UPDATE_INTERVAL 20 ms),
the navigator task at the position controller's rate (ModeExecutor), attitude/rate control every tick.
"""

from __future__ import annotations

import math
from typing import Final

from sitl_emu.commander.commander import Commander
from sitl_emu.control.cascade import MulticopterControl
from sitl_emu.control.position import PositionOutput
from sitl_emu.control.qmath import isfinite, norm
from sitl_emu.flight_tasks.core import IDLE_ACC_Z_M_S2
from sitl_emu.flight_tasks.mode_executor import ExecutorOutput, ModeExecutor
from sitl_emu.geo import GeoRef
from sitl_emu.navigator.setpoint import NavInput, SetpointType
from sitl_emu.params import ParamRegistry
from sitl_emu.params.settings import cascade_settings
from sitl_emu.physics import RigidBodyState
from sitl_emu.px4 import AUTO_MODES, NavState
from sitl_emu.types import NAN3, OffboardControlMode, TrajectorySetpoint, Vec3, Vec4
from sitl_emu.vehicle.land_detector import LandDetector, LandDetectorInput, LandDetectorState

LAND_DETECTOR_PERIOD_US: Final = 20_000
# Modes in which PX4's mc_pos_control runs on a multicopter (ModeUtil/control_mode.cpp: altitude, climb-rate, position,
# velocity or acceleration control), armed or not. While it is not flying it publishes the idle setpoint.
POSITION_CONTROLLED: Final = frozenset({NavState.ALTCTL, NavState.POSCTL, NavState.POSITION_SLOW,
                                        NavState.ALTITUDE_CRUISE, NavState.ORBIT, *AUTO_MODES})
ZERO3: Final = (0.0, 0.0, 0.0)
# (local setpoint, attitude setpoint, rate setpoint, collective thrust) as PX4's controllers publish them
Setpoints = tuple[TrajectorySetpoint | None, Vec4 | None, Vec3, float]


class ControlChain:
    """Mode executor -> control cascade -> (physics, in the vehicle) -> land detector, with the adapters Vehicle.step
    calls."""

    def __init__(self, params: ParamRegistry) -> None:
        self.params = params
        self.control = MulticopterControl(cascade_settings(params))
        self._params_watch = params.changes.watch()  # params/changes.py
        self.executor = ModeExecutor(params)
        self._detector = LandDetector(params)
        self.ground_contact = False
        # the land detector runs when now_us >= _land_next_us (every LAND_DETECTOR_PERIOD_US) or when arming changed
        self._land_next_us = -(1 << 62)
        self._land_armed = False

    def nav_input(self, now_us: int, est: RigidBodyState, c: Commander, ref: GeoRef) -> NavInput:
        """What the navigator task sees (flight_tasks/core.py NavInput)."""
        home = c.home
        local = self.control.position_output
        return NavInput(now_us, est.pos_ned_m, est.vel_ned_m_s, self.control.heading_rad(est),
                        home.pos_ned_m if home is not None else (0.0, 0.0, 0.0),
                        home.yaw_rad if home is not None else 0.0, c.landed, c.armed,
                        self.control.takeoff.state, ref.alt_amsl_m,
                        local.velocity_sp_ned_m_s if local is not None else NAN3)

    def control_update(self, est: RigidBodyState, out: ExecutorOutput, armed: bool, landed: bool, now_us: int,
                       dt_s: float) -> Vec4:
        """The cascade with the task's want_takeoff (auto modes) and the land detector's ground contact."""
        if self._params_watch.changed():  # a parameter changed: new controller settings
            self.control.settings = cascade_settings(self.params)
        return self.control.update(est, out.trajectory, out.attitude, armed, landed, now_us, dt_s,
                                   ground_contact=self.ground_contact, want_takeoff=out.want_takeoff)

    def land(self, est: RigidBodyState, armed: bool, out: ExecutorOutput, now_us: int) -> LandDetectorState | None:
        """Run the land detector on the new state when it is due: at 50 Hz, and at once when arming changes. Its new
        state (PX4's vehicle_land_detected), or None when it did not run this tick. `out` is this tick's executor
        output: whether the climb rate is controlled (see climb_rate_controlled)."""
        if now_us < self._land_next_us and armed == self._land_armed:
            return None
        self._land_next_us, self._land_armed = now_us + LAND_DETECTOR_PERIOD_US, armed
        ctrl = self.control
        state = self._detector.update(LandDetectorInput(
            time_us=now_us, armed=armed, vel_ned_m_s=est.vel_ned_m_s, rates_frd_rad_s=est.rates_frd_rad_s,
            specific_force_norm_m_s2=norm(est.specific_force_frd), thrust_setpoint=ctrl.thrust_setpoint,
            hover_thrust=ctrl.hover_thrust, setpoint_vz_m_s=descent_vz(ctrl.position_output),
            in_descent_mode=climb_rate_controlled(out)))
        self.ground_contact = state.ground_contact
        return state


def climb_rate_controlled(out: ExecutorOutput) -> bool:
    """PX4's control_mode.flag_control_climb_rate_enabled: auto modes and offboard position/velocity/acceleration
    (not offboard attitude/rates, not manual modes)."""
    return out.attitude is None and out.setpoint_type is not SetpointType.NONE


def published_setpoints(ctrl: MulticopterControl, nav_state: NavState, armed: bool,
                        offboard_last: OffboardControlMode | None, yaw_rad: float) -> Setpoints:
    """What the controllers publish (vehicle_local_position_setpoint, vehicle_attitude_setpoint, rates, thrust).

    Armed: the cascade's own. Disarmed, the cascade rests, but PX4's mc_pos_control keeps running in every
    position-controlled mode (MulticopterPositionControl.cpp): not yet taken off, it flies the idle setpoint (no
    position or velocity, acceleration 0,0,+100, i.e. no thrust) and publishes it with the yaw setpoint at the current
    heading and no yaw rate; its attitude setpoint is then level at that heading with zero thrust. So a ground station
    sees POSITION_TARGET_LOCAL_NED and ATTITUDE_TARGET at rest, as from PX4.
    """
    if armed or not _position_controlled(nav_state, offboard_last):
        return ctrl.local_setpoint, ctrl.attitude_setpoint_q_wxyz, ctrl.rates_setpoint_rad_s, ctrl.thrust_setpoint
    idle = TrajectorySetpoint(NAN3, NAN3, (0.0, 0.0, IDLE_ACC_Z_M_S2), yaw_rad, 0.0)
    half = 0.5 * yaw_rad
    return idle, (math.cos(half), 0.0, 0.0, math.sin(half)), ZERO3, 0.0


def _position_controlled(nav_state: NavState, offboard_last: OffboardControlMode | None) -> bool:
    if nav_state is NavState.OFFBOARD:  # control_mode.cpp: position, velocity or acceleration setpoints
        return offboard_last is not None and (offboard_last.position or offboard_last.velocity
                                              or offboard_last.acceleration)
    return nav_state in POSITION_CONTROLLED


def descent_vz(sp: PositionOutput | None) -> float:
    """The vertical velocity setpoint the land detector judges "descending" by (from the last position-control
    cycle's output, the local setpoint's source).

    MulticopterLandDetector.cpp _get_ground_contact_state also counts the idle setpoint (acceleration z >= 100,
    which the controller commands once it has ground contact) as descending; LandDetectorInput only carries vz,
    so an idle setpoint is passed as a large downward velocity.
    """
    if sp is None:
        return math.nan
    acc_z = sp.acceleration_sp_ned_m_s2[2]
    if isfinite(acc_z) and acc_z >= IDLE_ACC_Z_M_S2:
        return 1e3
    return sp.velocity_sp_ned_m_s[2]
