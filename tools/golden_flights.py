"""Hash every tick's truth state of a few scripted flights: a refactoring of the controllers or the physics that keeps
the maths must keep every hash.

usage: .venv/bin/python tools/golden_flights.py [--record FILE | --check FILE]

Without options it prints one sha256 per flight. The flights cover the auto modes (takeoff, hold, land), offboard
position / velocity / acceleration / attitude / body-rate setpoints, an invalid setpoint (the failsafe), parameter
changes in flight, wind, estimate noise, and the bare physics + control loop (sitl_emu.testing.harness).
"""

from __future__ import annotations

import hashlib
import json
import math
import struct
import sys
from collections.abc import Callable
from pathlib import Path

from sitl_emu.disturbance.estimate import EstimateNoiseSettings
from sitl_emu.physics import RIGID_BODY_FIELDS, RigidBodyState
from sitl_emu.px4 import MavCmd, NavState, custom_mode, decode_custom_mode
from sitl_emu.testing.harness import ClosedLoop, hover_loop
from sitl_emu.types import AttitudeSetpoint, OffboardControlMode, TrajectorySetpoint, VehicleCommand
from sitl_emu.vehicle.vehicle import Vehicle

NAN = math.nan


class Hasher:
    def __init__(self) -> None:
        self._h = hashlib.sha256()

    def state(self, s: RigidBodyState) -> None:
        for name in RIGID_BODY_FIELDS:
            value = getattr(s, name)
            if isinstance(value, tuple):
                self._h.update(struct.pack(f"<{len(value)}d", *value))
            else:
                self._h.update(repr(value).encode())

    def extra(self, *values: object) -> None:
        self._h.update(repr(values).encode())

    def hexdigest(self) -> str:
        return self._h.hexdigest()


def _command(v: Vehicle, command: int, *params: float) -> None:
    v.handle_command(VehicleCommand(command, tuple(params) + (NAN,) * (7 - len(params))))


def _offboard(v: Vehicle) -> None:
    main_mode, sub = decode_custom_mode(custom_mode(NavState.OFFBOARD))
    _command(v, MavCmd.DO_SET_MODE, 1 | 128, main_mode, sub)


def _runner(v: Vehicle, h: Hasher) -> Callable[..., None]:
    def run(seconds: float, mode: OffboardControlMode | None = None, sp: TrajectorySetpoint | None = None,
            att: AttitudeSetpoint | None = None) -> None:
        end = v.time_us + round(seconds * 1e6)
        while v.time_us < end:
            if mode is not None and v.time_us % 40_000 == 0:
                v.offboard_input(mode, sp, att)
            v.step()
            h.state(v._state)
            if v.time_us % 100_000 == 0:
                s = v.snapshot()
                h.extra(s.nav_state, s.landed_state, s.thrust_setpoint, s.armed)
    return run


def _takeoff(v: Vehicle, run: Callable[..., None]) -> None:
    run(2.5)
    _command(v, MavCmd.COMPONENT_ARM_DISARM, 1.0)
    _command(v, MavCmd.NAV_TAKEOFF)
    run(10.0)


def flight_offboard_position(noise: bool) -> str:
    h = Hasher()
    v = Vehicle(seed=3, estimate_noise=EstimateNoiseSettings(pos_white_m=0.05) if noise else None)
    run = _runner(v, h)
    _takeoff(v, run)
    pos = OffboardControlMode(position=True)
    run(0.5, pos, TrajectorySetpoint(position_ned_m=(0.0, 0.0, -2.5)))
    _offboard(v)
    run(6.0, pos, TrajectorySetpoint(position_ned_m=(20.0, -8.0, -6.0), yaw_rad=2.0))
    v.params.set("MPC_XY_VEL_MAX", 4.0)
    v.params.set("MC_ROLLRATE_P", 0.2)
    v.params.set("MPC_TILTMAX_AIR", 30.0)
    run(6.0, pos, TrajectorySetpoint(position_ned_m=(-5.0, 5.0, -3.0), yaw_rad=-2.5))
    run(3.0)  # stream lost -> failsafe
    _command(v, MavCmd.NAV_LAND)
    run(12.0)
    return h.hexdigest()


def flight_offboard_kinds() -> str:
    h = Hasher()
    v = Vehicle(seed=1)
    v.params.set("SIH_WIND_N", 3.0)
    v.params.set("SIH_WIND_E", -1.5)
    run = _runner(v, h)
    _takeoff(v, run)
    vel = OffboardControlMode(velocity=True)
    run(0.5, vel, TrajectorySetpoint(velocity_ned_m_s=(0.0, 0.0, 0.0)))
    _offboard(v)
    run(4.0, vel, TrajectorySetpoint(velocity_ned_m_s=(6.0, 2.0, -1.0), yawspeed_rad_s=0.8))
    acc = OffboardControlMode(acceleration=True)
    run(2.0, acc, TrajectorySetpoint(acceleration_ned_m_s2=(1.0, -2.0, 0.5)))
    both = OffboardControlMode(position=True, velocity=True)
    run(3.0, both, TrajectorySetpoint(position_ned_m=(3.0, 3.0, -5.0), velocity_ned_m_s=(1.0, 0.5, NAN)))
    bad = TrajectorySetpoint(position_ned_m=(1.0, NAN, -3.0))  # invalid: x without y -> hold then failsafe
    run(1.5, OffboardControlMode(position=True), bad)
    att = OffboardControlMode(attitude=True)
    q = (math.cos(0.15), math.sin(0.15), 0.0, 0.0)
    run(1.5, att, att=AttitudeSetpoint(q_wxyz=q, body_rates_rad_s=(NAN, NAN, 0.5), thrust_body=(0.0, 0.0, -0.55)))
    rates = OffboardControlMode(body_rate=True)
    run(0.8, rates, att=AttitudeSetpoint(body_rates_rad_s=(0.3, -0.2, 1.0), thrust_body=(0.0, 0.0, -0.6)))
    run(1.0, att, att=AttitudeSetpoint(q_wxyz=(0.0, 0.0, 0.0, 1.0), thrust_body=(0.0, 0.0, -0.9)))
    run(4.0, OffboardControlMode(position=True), TrajectorySetpoint(position_ned_m=(0.0, 0.0, -4.0)))
    _command(v, MavCmd.NAV_LAND)
    run(15.0)
    return h.hexdigest()


def flight_harness() -> str:
    h = Hasher()
    loop = hover_loop(2.5)
    for s in (loop.state,):
        h.state(s)
    trace = loop.run(4.0, lambda t: TrajectorySetpoint(position_ned_m=(10.0, 0.0, -2.5)))
    trace = loop.run(3.0, lambda t: TrajectorySetpoint(velocity_ned_m_s=(0.0, 5.0 * math.sin(t), -0.5)), trace=trace)
    trace = loop.run(2.0, lambda t: None, attitude=lambda t: AttitudeSetpoint(
        q_wxyz=(math.cos(0.6), 0.0, math.sin(0.6), 0.0), thrust_body=(0.0, 0.0, -0.7)), trace=trace)
    trace = loop.run(1.0, lambda t: None, trace=trace)  # no setpoint: idle
    loop2 = ClosedLoop(flying=True, state=RigidBodyState(pos_ned_m=(0.0, 0.0, -10.0), on_ground=False))
    trace = loop2.run(6.0, lambda t: TrajectorySetpoint(position_ned_m=(0.0, 0.0, -1.0), yaw_rad=3.0), trace=trace)
    for s, m, tk, fs in zip(trace.states, trace.motors, trace.takeoff_state, trace.failsafe, strict=True):
        h.state(s)
        h.extra(m, tk, fs)
    return h.hexdigest()


FLIGHTS: dict[str, Callable[[], str]] = {
    "offboard_position": lambda: flight_offboard_position(False),
    "offboard_position_noise": lambda: flight_offboard_position(True),
    "offboard_kinds_wind": flight_offboard_kinds,
    "harness": flight_harness,
}


def main(argv: list[str]) -> int:
    got = {name: fn() for name, fn in FLIGHTS.items()}
    if argv[:1] == ["--record"]:
        Path(argv[1]).write_text(json.dumps(got, indent=1) + "\n")
    if argv[:1] == ["--check"]:
        want = json.loads(Path(argv[1]).read_text())
        bad = [name for name in FLIGHTS if want.get(name) != got[name]]
        print("golden SAME" if not bad else f"golden DIFFERS: {', '.join(bad)}")
        return 1 if bad else 0
    for name, digest in got.items():
        print(f"{name}: {digest}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
