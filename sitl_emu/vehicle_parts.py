"""The components Vehicle.step drives, behind small adapters: control cascade, mode executor, land detector.

Each adapter turns the vehicle's state into the component's input type, so vehicle.py stays a readable list of
steps. Rates follow PX4: the land detector runs at 50 Hz (LandDetector.h LAND_DETECTOR_UPDATE_INTERVAL 20 ms),
the navigator task at the position controller's rate (ModeExecutor), attitude/rate control every tick.
"""

from __future__ import annotations

import math

from sitl_emu.control.cascade import MulticopterControl
from sitl_emu.flight.commander import Commander
from sitl_emu.flight.land_detector import LandDetector
from sitl_emu.flight.mode_executor import ExecutorOutput, ModeExecutor
from sitl_emu.flight.tasks import NavInput
from sitl_emu.geo import GeoRef
from sitl_emu.params import ParamRegistry
from sitl_emu.params.settings import cascade_settings
from sitl_emu.physics import RigidBodyState
from sitl_emu.types import TrajectorySetpoint, Vec4

LAND_DETECTOR_PERIOD_US = 20_000
IDLE_ACC_Z_M_S2 = 100.0  # the controller's "no thrust" setpoint (FlightTaskAuto / MulticopterPositionControl)


def yaw_of(q: Vec4) -> float:
    w, x, y, z = q
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


class Parts:
    """Control cascade + mode executor + land detector, with the adapters Vehicle.step calls."""

    def __init__(self, params: ParamRegistry) -> None:
        self.params = params
        self.control = MulticopterControl(cascade_settings(params))
        self._control_params_version = params.version
        self.executor = ModeExecutor(params)
        self._detector = LandDetector(params)
        self.ground_contact = False
        # the land detector runs when now_us >= _ld_next_us (every LAND_DETECTOR_PERIOD_US) or when arming changed
        self._ld_next_us = -(1 << 62)
        self._ld_armed = False
        self._ld_out = (True, True)

    def nav_input(self, now_us: int, est: RigidBodyState, c: Commander, ref: GeoRef) -> NavInput:
        """What the navigator task sees (tasks_core.NavInput)."""
        home = c.home
        return NavInput(now_us, est.pos_ned_m, est.vel_ned_m_s, yaw_of(est.q_wxyz),  # positional: faster
                        home.pos_ned_m if home else (0.0, 0.0, 0.0), home.yaw_rad if home else 0.0, c.landed, c.armed,
                        str(self.control.takeoff_state), ref.alt_amsl_m)

    def control_update(self, est: RigidBodyState, out: ExecutorOutput, armed: bool, landed: bool, now_us: int,
                       dt_s: float) -> Vec4:
        """The cascade with the task's want_takeoff (auto modes) and the land detector's ground contact."""
        if self.params.version != self._control_params_version:  # a parameter changed: new controller settings
            self._control_params_version = self.params.version
            self.control.settings = cascade_settings(self.params)
        return self.control.update(est, out.trajectory, out.attitude, armed, landed, now_us, dt_s,
                                   ground_contact=self.ground_contact, want_takeoff=out.want_takeoff)

    def land(self, est: RigidBodyState, c: Commander, climb_rate_controlled: bool,
             now_us: int) -> tuple[bool, bool]:
        """Run the land detector on the new state at 50 Hz (at once when arming changes); (landed, maybe_landed).

        `climb_rate_controlled` is PX4's control_mode.flag_control_climb_rate_enabled: auto modes and offboard
        position/velocity/acceleration (not offboard attitude/rates, not manual modes)."""
        if now_us < self._ld_next_us and c.armed == self._ld_armed:
            return self._ld_out
        self._ld_next_us, self._ld_armed = now_us + LAND_DETECTOR_PERIOD_US, c.armed
        f = est.specific_force_frd
        ctrl = self.control
        # LandDetector.update(LandDetectorInput(...)) without the input/output objects
        landed, maybe_landed, ground_contact = self._detector.update_values(
            now_us, c.armed, est.vel_ned_m_s, est.rates_frd_rad_s, math.sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]),
            ctrl.thrust_setpoint, ctrl.hover_thrust, descent_vz(ctrl.local_setpoint), climb_rate_controlled)
        self.ground_contact = bool(ground_contact)
        out = self._ld_out = (landed, maybe_landed)
        return out


def descent_vz(sp: TrajectorySetpoint | None) -> float:
    """The vertical velocity setpoint the land detector judges "descending" by.

    MulticopterLandDetector.cpp _get_ground_contact_state also counts the idle setpoint (acceleration z >= 100,
    which the controller commands once it has ground contact) as descending; LandDetectorInput only carries vz,
    so an idle setpoint is passed as a large downward velocity.
    """
    if sp is None:
        return math.nan
    acc_z = sp.acceleration_ned_m_s2[2]
    if math.isfinite(acc_z) and acc_z >= IDLE_ACC_Z_M_S2:
        return 1e3
    return sp.velocity_ned_m_s[2]
