"""The faults and disturbances of one vehicle, between the controllers, the physics and the commander.

Vehicle.step asks `VehicleFaults` for: the motor outputs after injected motor failures, the wind for the physics,
the estimate (the truth, or with estimator noise), and once per commander cycle `update` turns the battery, the GPS,
the failure detector and the ground-station link into the commander's failsafe flags (commander/fault_failsafes.py)
and PX4's texts. With no wind, no noise and nothing injected, nothing here changes what the vehicle does.

- Battery: commander/battery.py (BatterySimulator.cpp; texts: HealthAndArmingChecks/checks/batteryCheck.cpp and the
  failsafe framework's warning events, failsafe/framework.cpp notifyUser).
- GPS off: the estimator (ekf2) dead-reckons on the IMU for EKF2_NOAID_TOUT, then has no horizontal position; the
  commander's mode checks (commander/arming.py) then see no position and the failsafe falls back (Hold -> Land ->
  Descend, failsafe.cpp checkModeFallback).
- Failure detector (commander/failure_detector/FailureDetector.cpp updateAttitudeStatus): while armed, roll beyond
  FD_FAIL_R for FD_FAIL_R_TTRI or pitch beyond FD_FAIL_P for FD_FAIL_P_TTRI -> fd_critical_failure.
- GCS link (Commander.cpp dataLinkCheck): a GCS heartbeat seen, then none for COM_DL_LOSS_T -> "Connection to ground
  station lost", gcs_connection_lost (NAV_DLL_ACT); a heartbeat again -> "GCS connection regained".
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Final

from sitl_emu.commander import failure_injection as fi
from sitl_emu.commander.battery import (
    HEALTH_TEXTS,
    WARN_EVENTS,
    WARNING_EMERGENCY,
    BatterySettings,
    BatterySimulator,
    battery_action,
)
from sitl_emu.commander.fault_failsafes import FaultFlags
from sitl_emu.control.qmath import euler_from_q
from sitl_emu.disturbance.estimate import EstimateNoise, EstimateNoiseSettings
from sitl_emu.disturbance.wind import WindModel, WindSettings
from sitl_emu.params import ParamRegistry
from sitl_emu.physics import RigidBodyState
from sitl_emu.px4 import MavResult, Severity
from sitl_emu.types import CommandAck, Vec3, VehicleCommand

if TYPE_CHECKING:
    import numpy as np

# emit(severity, module, text, is_event, statustext)
Emit = Callable[[Severity, str, str, bool, bool], None]
# The estimator noise draws from the seed's own stream, np.random.default_rng(seed); the wind from a second one
WIND_STREAM: Final = 1  # np.random.default_rng([seed, WIND_STREAM])


@dataclass(frozen=True, slots=True)
class MonitorSettings:
    """The parameters read here, once per parameter change."""

    battery: BatterySettings
    low_bat_act: int  # COM_LOW_BAT_ACT
    noaid_us: int  # EKF2_NOAID_TOUT
    dl_loss_us: int  # COM_DL_LOSS_T
    fd_max_rad: tuple[float, float]  # FD_FAIL_R, FD_FAIL_P (0: off)
    fd_ttri_us: tuple[int, int]  # FD_FAIL_R_TTRI, FD_FAIL_P_TTRI
    sih_wind_from: tuple[float, float]  # SIH_WIND_N, SIH_WIND_E
    fd_cos_tilt: float  # cos of the smaller of FD_FAIL_R / FD_FAIL_P: a tilt with a larger cosine breaks neither

    @classmethod
    def from_params(cls, p: ParamRegistry) -> MonitorSettings:
        g = p.get
        fd_max_rad = (math.radians(abs(g("FD_FAIL_R"))), math.radians(abs(g("FD_FAIL_P"))))
        return cls(BatterySettings.from_params(p), int(p["COM_LOW_BAT_ACT"]), int(p["EKF2_NOAID_TOUT"]),
                   int(p["COM_DL_LOSS_T"]) * 1_000_000, fd_max_rad,
                   (round(g("FD_FAIL_R_TTRI") * 1e6), round(g("FD_FAIL_P_TTRI") * 1e6)),
                   (g("SIH_WIND_N"), g("SIH_WIND_E")), math.cos(min(fd_max_rad)))


class VehicleFaults:
    """See the module docstring. `flags` is the commander's FaultFlags, written here."""

    def __init__(self, params: ParamRegistry, flags: FaultFlags, emit: Emit, *, seed: int, dt_s: float,
                 wind: WindSettings | None = None, noise: EstimateNoiseSettings | None = None) -> None:
        self.params, self.flags, self._emit = params, flags, emit
        self.failures = fi.FailureTable()
        self._motor_stop = 0  # the motors' OFF mask in `failures`, kept here as it is read every tick
        self.manager_running = int(params["SYS_FAILURE_EN"]) == 1  # reboot_required: read at boot
        self.battery = BatterySimulator()
        self._settings = MonitorSettings.from_params(params)
        self._params_watch = params.changes.watch()  # params/changes.py
        self.wind = WindModel(wind, dt_s, _rng([seed, WIND_STREAM])) if wind and wind.active else None
        self.noise = EstimateNoise(noise, _rng(seed)) if noise is not None and noise.active else None
        self._gps_off_us: int | None = None
        self._fd_since_us: list[int | None] = [None, None]  # roll, pitch beyond their limit since
        self._last_gcs_us: int | None = None
        self._armed = False

    # ---- per tick -----------------------------------------------------------------------------------------------
    def motors(self, cmd: tuple[float, float, float, float]) -> tuple[float, float, float, float]:
        """The mixer's commands with the stopped motors at 0 (ControlAllocator motor_stop_mask)."""
        stop = self._motor_stop
        if not stop:
            return cmd
        m0, m1, m2, m3 = cmd
        return (0.0 if stop & 1 else m0, 0.0 if stop & 2 else m1, 0.0 if stop & 4 else m2, 0.0 if stop & 8 else m3)

    def wind_at(self, time_us: int, state: RigidBodyState) -> Vec3 | None:
        """The air mass velocity for the physics; None: the physics' own (SIH_WIND_N/E, as without this module)."""
        if self.wind is None:
            return None
        return self.wind.sample(time_us, -state.pos_ned_m[2], self.settings.sih_wind_from)

    def estimate(self, truth: RigidBodyState, dt_s: float) -> RigidBodyState:
        """The estimate of this tick: the truth itself without estimator noise (disturbance/estimate.py)."""
        return truth if self.noise is None else self.noise.apply(truth, dt_s)

    @property
    def settings(self) -> MonitorSettings:
        if self._params_watch.changed():
            self._settings = MonitorSettings.from_params(self.params)
        return self._settings

    # ---- per commander cycle ------------------------------------------------------------------------------------
    def update(self, now_us: int, armed: bool, est: RigidBodyState) -> None:
        f, s = self.flags, self.settings
        if armed and not self._armed:
            f.armed_at_us, f.battery_warning_at_arming = now_us, f.battery_warning
        self._armed = armed
        self._update_battery(now_us, armed, s)
        f.position_lost = self._gps_off_us is not None and now_us - self._gps_off_us >= s.noaid_us
        f.fd_critical_failure = self._attitude_failed(now_us, armed, est, s)
        self._check_gcs_link(now_us, s)

    def _update_battery(self, now_us: int, armed: bool, s: MonitorSettings) -> None:
        bat, before = self.battery, self.battery.warning
        bat.update(now_us, armed, s.battery)
        self.flags.battery_warning = bat.warning
        if bat.warning > before:
            severity = Severity.EMERGENCY if bat.warning == WARNING_EMERGENCY else Severity.CRITICAL
            self._emit(severity, "commander", HEALTH_TEXTS[bat.warning], True, True)
            action = battery_action(bat.warning, s.low_bat_act, self.flags.battery_warning_at_arming)
            if armed and action is None:  # a warning-only failsafe: framework.cpp's event, not a STATUSTEXT
                self._emit(Severity.WARNING, "commander", WARN_EVENTS[bat.warning], True, False)

    def _attitude_failed(self, now_us: int, armed: bool, est: RigidBodyState, s: MonitorSettings) -> bool:
        """Roll or pitch beyond its limit for its trigger time (each with its own hysteresis, as PX4's)."""
        since = self._fd_since_us
        q = est.q_wxyz
        qx, qy = q[1], q[2]  # not `_, qx, qy, _ = q`: compiled, `_` holds an object and boxes its floats
        # cos(tilt) = cos(roll) cos(pitch): a vehicle tilted less than both limits has neither beyond (cheap test)
        if not armed or 1.0 - 2.0 * (qx * qx + qy * qy) > s.fd_cos_tilt:
            since[0] = since[1] = None
            return False
        failed = False
        for axis, angle in enumerate(euler_from_q(est.q_wxyz)[:2]):
            limit = s.fd_max_rad[axis]
            if not (limit > 0.0 and abs(angle) > limit):
                since[axis] = None
                continue
            start = since[axis]
            if start is None:
                since[axis] = start = now_us
            failed = failed or now_us - start >= s.fd_ttri_us[axis]
        return failed

    def _check_gcs_link(self, now_us: int, s: MonitorSettings) -> None:
        last = self._last_gcs_us
        if last is None or self.flags.gcs_connection_lost:
            return
        if now_us - last > s.dl_loss_us:
            self.flags.gcs_connection_lost = True
            self._emit(Severity.INFO, "commander", "Connection to ground station lost", True, True)

    @property
    def gps_fix_type(self) -> int:
        """sensor_gps_sim's fix: 3D, or nothing while GPS is failed (the driver publishes no sample)."""
        return 0 if self._gps_off_us is not None else 3

    # ---- inputs -------------------------------------------------------------------------------------------------
    def gcs_heartbeat(self, now_us: int) -> None:
        """A heartbeat from a ground station (MAV_TYPE_GCS)."""
        if self.flags.gcs_connection_lost:
            self.flags.gcs_connection_lost = False
            self._emit(Severity.INFO, "commander", "GCS connection regained", True, True)
        self._last_gcs_us = now_us

    def inject(self, cmd: VehicleCommand, now_us: int) -> CommandAck | None:
        """MAV_CMD_INJECT_FAILURE: DENIED by the mavlink module while SYS_FAILURE_EN is 0 (MAVLink only: the `failure`
        command checks it itself); no ACK if the manager did not start at boot."""
        if cmd.from_external and int(self.params["SYS_FAILURE_EN"]) != 1:
            return CommandAck(cmd.command, int(MavResult.DENIED))
        if not self.manager_running:
            return None
        unit, ftype, mask = fi.command_target(cmd.param(1), cmd.param(2), cmd.param(3), cmd.param(4))
        result = self.failures.inject(unit, ftype, mask)
        if result == MavResult.ACCEPTED and mask:
            self._emit(Severity.WARNING, "failure_injection_manager", fi.announcement(unit, ftype, mask), False, True)
            self._apply(unit, now_us)
        return CommandAck(cmd.command, int(result))

    def _apply(self, unit: int, now_us: int) -> None:
        if unit == fi.GPS:
            off = bool(self.failures.mask(fi.GPS))
            self._gps_off_us = (self._gps_off_us if self._gps_off_us is not None else now_us) if off else None
        elif unit == fi.BATTERY:
            self.battery.failed = bool(self.failures.mask(fi.BATTERY))
        elif unit == fi.MOTOR:
            self._motor_stop = self.failures.mask(fi.MOTOR)


def _rng(seed: int | list[int]) -> np.random.Generator:
    """numpy's seeded generator, numpy imported only here: a vehicle without wind or noise never loads it (its import
    costs tens of ms, and its BLAS threads then spin for a while on the process's CPU time)."""
    import numpy as np

    return np.random.default_rng(seed)
