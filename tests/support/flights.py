"""A scripted flight of the vehicle core, recorded tick by tick: the determinism and compiled-build tests compare it."""

from __future__ import annotations

import math

from sitl_emu.params import default_registry
from sitl_emu.px4 import MavCmd, NavState, custom_mode, decode_custom_mode
from sitl_emu.types import CommandAck, OffboardControlMode, TrajectorySetpoint, VehicleCommand
from sitl_emu.vehicle.vehicle import Vehicle

NAN = math.nan
POS = OffboardControlMode(position=True)


def scripted_flight(v: Vehicle) -> list[tuple]:
    """Arm, take off, go offboard, step, lose the stream, land: record snapshots and events as plain tuples."""
    out: list[tuple] = []

    def run(seconds: float, sp: TrajectorySetpoint | None = None) -> None:
        end = v.time_us + int(seconds * 1e6)
        while v.time_us < end:
            if sp is not None and v.time_us % 50_000 == 0:
                v.offboard_input(POS, sp)
            v.step()
            if v.time_us % 100_000 == 0:
                s = v.snapshot()
                out.append((s.time_us, s.armed, s.nav_state, s.landed_state, s.pos_ned_m, s.vel_ned_m_s, s.q_wxyz,
                            s.motors, s.thrust_setpoint))

    run(2.5)
    v.handle_command(VehicleCommand(MavCmd.COMPONENT_ARM_DISARM, (1.0, 0.0) + (NAN,) * 5))
    v.handle_command(VehicleCommand(MavCmd.NAV_TAKEOFF, (NAN,) * 7))
    run(12.0)
    sp = TrajectorySetpoint(position_ned_m=(0.0, 0.0, -2.5))
    run(0.5, sp)
    main, sub = decode_custom_mode(custom_mode(NavState.OFFBOARD))
    v.handle_command(VehicleCommand(MavCmd.DO_SET_MODE, (1.0, main, sub) + (NAN,) * 4))
    run(6.0, TrajectorySetpoint(position_ned_m=(5.0, 3.0, -4.0), yaw_rad=1.0))
    run(3.0)  # stream lost -> Return
    v.handle_command(VehicleCommand(MavCmd.NAV_LAND, (NAN,) * 7))
    run(10.0)
    out.extend((e.seq, e.time_us, e.text) for e in v.events_after(0))
    return out


def command(v: Vehicle, cmd: int, *params: float, external: bool = True) -> CommandAck | None:
    """The vehicle's answer to a command with these params (NaN for the rest), as a ground station sends it."""
    return v.handle_command(VehicleCommand(cmd, tuple(params) + (NAN,) * (7 - len(params)), from_external=external))


def hovering_vehicle(**params: float) -> Vehicle:
    """A vehicle with these parameters, armed and taken off, holding in AUTO.LOITER after the take-off."""
    reg = default_registry()
    for name, value in params.items():
        reg.set(name, value)
    v = Vehicle(params=reg)
    v.run_for(2.5)
    command(v, MavCmd.COMPONENT_ARM_DISARM, 1.0, 0.0)
    command(v, MavCmd.NAV_TAKEOFF)
    v.run_for(8.0)
    assert v.snapshot().nav_state is NavState.AUTO_LOITER and not v.commander.landed
    return v
