"""The flight log's bytes are fixed: a lockstep flight that logs every topic gives the same files, byte for byte.

The flight (SDLOG_MODE 1: the first log from boot to the first disarming, then one per flight) waits for the
pre-flight checks, sends sticks, arms, takes off, changes a parameter in flight, flies offboard, loses the
setpoint stream (failsafe), lands and disarms, then arms and disarms once more. Every topic of topics.py is in the
first log, and the state topics change several times. The hash was taken with the logger as it was before its
speed-ups (issue 28), then set again for the flight itself changing (MPC_Z_ERR_MAX in the auto tasks' vertical
trajectory, PX4 main's failsafe wording): the logger's speed-ups were checked to give the same hash as the logger
before them on that code. A change to the logger that keeps its output must keep the hash; a change that alters the
flight or the log on purpose sets the new hash and says why.
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Callable
from pathlib import Path

from support.log_flight import log_files

from sitl_emu.px4 import MavCmd, NavState, custom_mode, decode_custom_mode
from sitl_emu.testing.sim import Sim
from sitl_emu.types import ManualControlSetpoint, OffboardControlMode, TrajectorySetpoint, VehicleCommand
from sitl_emu.vehicle.vehicle import Vehicle

NAN = math.nan
EPOCH_UNIX_US = 1_700_000_000_000_000  # a fixed boot time (the file names and boot_time_utc_us hold it)
EXPECTED_SHA256 = "17e81ce21554281534eb5684fba5db2333f8635c30a8d1c4a1253a5a06e3f056"


def _command(v: Vehicle, cmd: int, *params: float) -> None:
    v.handle_command(VehicleCommand(cmd, tuple(params) + (NAN,) * (7 - len(params))))


def _set_mode(v: Vehicle, nav_state: NavState) -> None:
    main, sub = decode_custom_mode(custom_mode(nav_state))
    _command(v, MavCmd.DO_SET_MODE, 1.0, main, sub)


def _fly(sim: Sim, seconds: float, each_100ms: Callable[[], None] | None = None) -> None:
    for _ in range(round(seconds * 10)):
        if each_100ms is not None:
            each_100ms()
        sim.run_for(0.1)


def _flight(log_dir: Path) -> list[Path]:
    with Sim(log_dir=log_dir, params={"SDLOG_MODE": 1, "MIS_TAKEOFF_ALT": 3.0}) as sim:
        sim.nodes[0].epoch_unix_us = EPOCH_UNIX_US
        v = sim.vehicle(0)
        sim.run_until(lambda: v.snapshot().pre_flight_checks_pass, 30.0)
        _command(v, MavCmd.COMPONENT_ARM_DISARM, 1.0, 0.0)
        _command(v, MavCmd.NAV_TAKEOFF)
        _fly(sim, 8.0)
        v.params.set("MPC_XY_VEL_MAX", 7.5)
        sp = TrajectorySetpoint(position_ned_m=(5.0, 3.0, -4.0), yaw_rad=1.0)

        def offboard() -> None:
            v.offboard_input(OffboardControlMode(position=True), sp)

        _fly(sim, 0.5, offboard)
        _set_mode(v, NavState.OFFBOARD)
        _fly(sim, 5.0, offboard)
        _fly(sim, 2.0)  # the stream is lost: failsafe
        _command(v, MavCmd.NAV_LAND)
        sim.run_until(lambda: not v.commander.armed, 40.0)
        _fly(sim, 1.0)
        _set_mode(v, NavState.POSCTL)
        sticks = ManualControlSetpoint(roll=0.25, pitch=-0.5, yaw=0.125, throttle=0.0, buttons=3)

        def sticks_in() -> None:
            v.manual_control_input(sticks)

        _fly(sim, 1.0, sticks_in)
        _command(v, MavCmd.COMPONENT_ARM_DISARM, 1.0, 0.0)
        _fly(sim, 1.0, sticks_in)
        _command(v, MavCmd.COMPONENT_ARM_DISARM, 0.0, 21196.0)
        _fly(sim, 0.5)
    return log_files(log_dir)


def test_a_lockstep_flights_logs_are_byte_for_byte_the_same(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # a relative log folder: the "[logger] ./log/..." texts name no temporary path
    files = _flight(Path("log"))
    assert len(files) == 2, files
    digest = hashlib.sha256()
    for f in files:
        digest.update(f.as_posix().encode() + b"\0" + f.read_bytes())
    assert digest.hexdigest() == EXPECTED_SHA256
