"""The components Vehicle.step drives, behind small adapters: control cascade, mode executor, land detector.

Each adapter turns the vehicle's state into the component's input type, so vehicle.py stays a readable list of
steps. If a component module is not installed yet, a null stand-in keeps the vehicle usable (it then stays on the
ground): motors off, no setpoints, landed while on the ground.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import Any

from sitl_emu.flight.commander import Commander, NavCommand
from sitl_emu.geo import GeoRef
from sitl_emu.params import ParamRegistry
from sitl_emu.physics import RigidBodyState
from sitl_emu.px4 import NavState
from sitl_emu.types import NAN3, AttitudeSetpoint, OffboardControlMode, TrajectorySetpoint, Vec3, Vec4

log = logging.getLogger(__name__)

LAND_DETECTOR_PERIOD_US = 20_000  # land_detector runs at 50 Hz (LandDetector.h LAND_DETECTOR_UPDATE_INTERVAL)


@dataclass(frozen=True, slots=True)
class _NullOutput:
    trajectory: TrajectorySetpoint | None = None
    attitude: AttitudeSetpoint | None = None
    setpoint_type: str = "none"
    task_finished: bool = False
    messages: tuple = ()
    want_takeoff: bool | None = None


class _NullExecutor:
    task = None

    def offboard(self, mode: OffboardControlMode, trajectory: TrajectorySetpoint | None,
                 attitude: AttitudeSetpoint | None) -> None:
        pass

    def update(self, nav_state: NavState, armed: bool, now_us: int, nav_fn: Any, commands: list[NavCommand],
               ref: GeoRef, dt_s: float) -> _NullOutput:
        commands.clear()
        return _NullOutput()


class _NullControl:
    local_setpoint: TrajectorySetpoint | None = None
    attitude_setpoint_q_wxyz: Vec4 | None = None
    rates_setpoint_rad_s: Vec3 = NAN3
    thrust_setpoint: float = 0.0
    hover_thrust: float = 0.5

    def update(self, state: RigidBodyState, setpoint: TrajectorySetpoint | None, attitude_sp: AttitudeSetpoint | None,
               armed: bool, landed: bool, now_us: int, dt_s: float) -> Vec4:
        return (0.0, 0.0, 0.0, 0.0)

    def reset(self) -> None:
        pass


def _yaw(q: Vec4) -> float:
    w, x, y, z = q
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


class Parts:
    """Control cascade + mode executor + land detector, with the adapters Vehicle.step calls."""

    def __init__(self, params: ParamRegistry) -> None:
        self.params = params
        self.control: Any = _make_control(params)
        self.executor: Any = _make_executor(params)
        self._detector: Any = _make_land_detector(params)
        self.ground_contact = False
        self._ld_last_us: int | None = None
        self._ld_armed = False
        self._ld_out = (True, True)

    def nav_input(self, now_us: int, est: RigidBodyState, c: Commander, ref: GeoRef) -> Any:
        try:
            from sitl_emu.flight.tasks import NavInput
        except ImportError:
            return None
        home = c.home
        return NavInput(time_us=now_us, pos_ned_m=est.pos_ned_m, vel_ned_m_s=est.vel_ned_m_s,
                        yaw_rad=_yaw(est.q_wxyz), home_ned_m=home.pos_ned_m if home else (0.0, 0.0, 0.0),
                        home_yaw_rad=home.yaw_rad if home else 0.0, landed=c.landed, armed=c.armed,
                        takeoff_state=self.control_takeoff_state(), ref_alt_amsl_m=ref.alt_amsl_m)

    def control_takeoff_state(self) -> str:
        return str(getattr(self.control, "takeoff_state", "flight"))

    def control_update(self, est: RigidBodyState, out: Any, armed: bool, landed: bool, now_us: int,
                       dt_s: float) -> Vec4:
        """The cascade with the task's want_takeoff (auto modes) and the land detector's ground contact."""
        if isinstance(self.control, _NullControl):
            return self.control.update(est, out.trajectory, out.attitude, armed, landed, now_us, dt_s)
        return self.control.update(est, out.trajectory, out.attitude, armed, landed, now_us, dt_s,
                                   ground_contact=self.ground_contact, want_takeoff=out.want_takeoff)

    def land(self, est: RigidBodyState, c: Commander, climb_rate_controlled: bool,
             now_us: int) -> tuple[bool, bool]:
        """Run the land detector on the new state; (landed, maybe_landed).

        `climb_rate_controlled` is PX4's control_mode.flag_control_climb_rate_enabled: auto modes and offboard
        position/velocity/acceleration (not offboard attitude/rates, not manual modes)."""
        if self._detector is None:
            landed = est.on_ground or not c.armed
            return landed, landed
        if self._ld_last_us is not None and now_us - self._ld_last_us < LAND_DETECTOR_PERIOD_US \
                and c.armed == self._ld_armed:
            return self._ld_out
        self._ld_last_us, self._ld_armed = now_us, c.armed
        from sitl_emu.flight.land_detector import LandDetectorInput

        sp_vz = _descent_vz(self.control.local_setpoint)
        f = est.specific_force_frd
        out = self._detector.update(LandDetectorInput(
            time_us=now_us, armed=c.armed, vel_ned_m_s=est.vel_ned_m_s, rates_frd_rad_s=est.rates_frd_rad_s,
            specific_force_norm_m_s2=math.sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]),
            thrust_setpoint=self.control.thrust_setpoint, hover_thrust=self.control.hover_thrust,
            setpoint_vz_m_s=sp_vz, in_descent_mode=climb_rate_controlled))
        self.ground_contact = bool(out.ground_contact)
        self._ld_out = (out.landed, out.maybe_landed)
        return self._ld_out


def _descent_vz(sp: TrajectorySetpoint | None) -> float:
    """The vertical velocity setpoint the land detector judges "descending" by.

    MulticopterLandDetector.cpp _get_ground_contact_state also counts the idle setpoint (acceleration z >= 100,
    which the controller commands once it has ground contact) as descending; LandDetectorInput only carries vz,
    so an idle setpoint is passed as a large downward velocity.
    """
    if sp is None:
        return math.nan
    acc_z = sp.acceleration_ned_m_s2[2]
    if math.isfinite(acc_z) and acc_z >= 100.0:
        return 1e3
    return sp.velocity_ned_m_s[2]


def _make_control(params: ParamRegistry) -> Any:
    try:
        from sitl_emu.control.cascade import MulticopterControl
    except ImportError:
        log.warning("sitl_emu.control.cascade missing: motors stay off")
        return _NullControl()
    return MulticopterControl(params)


def _make_executor(params: ParamRegistry) -> Any:
    try:
        from sitl_emu.flight.mode_executor import ModeExecutor
    except ImportError:
        log.warning("sitl_emu.flight.tasks missing: no navigator tasks")
        return _NullExecutor()
    return ModeExecutor(params)


def _make_land_detector(params: ParamRegistry) -> Any:
    try:
        from sitl_emu.flight.land_detector import LandDetector
    except ImportError:
        log.warning("sitl_emu.flight.land_detector missing: landed = on the ground")
        return None
    return LandDetector(params)


def build_parts(params: ParamRegistry) -> Parts:
    return Parts(params)
