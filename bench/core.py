"""Core speed: simulated seconds per CPU second of one vehicle flying a fixed manoeuvre, no I/O (and with I/O).

The manoeuvre: boot, arm, NAV_TAKEOFF to 2.5 m, hold, OFFBOARD position step 10 m north, NAV_LAND, auto-disarm
(about 36 s of simulated flight, the same as `python -m sitl_emu.demo`).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

from sitl_emu.px4 import MavCmd, NavState, custom_mode, decode_custom_mode
from sitl_emu.types import OffboardControlMode, TrajectorySetpoint, VehicleCommand
from sitl_emu.vehicle.vehicle import Vehicle

NAN = math.nan
POS = OffboardControlMode(position=True)


def _command(v: Vehicle, command: int, *params: float) -> None:
    v.handle_command(VehicleCommand(command, tuple(params) + (NAN,) * (7 - len(params))))


def manoeuvre(v: Vehicle, after_step: Callable[[], None] | None = None) -> None:
    """Fly the fixed manoeuvre; `after_step` runs after every vehicle step (e.g. the node's I/O)."""
    stream: list[TrajectorySetpoint | None] = [None]
    next_us = [0]

    def run(seconds: float) -> None:
        end = v.time_us + round(seconds * 1e6)
        while v.time_us < end:
            sp = stream[0]
            if sp is not None and v.time_us >= next_us[0]:
                v.offboard_input(POS, sp)
                next_us[0] = v.time_us + 50_000
            v.step()
            if after_step is not None:
                after_step()

    run(2.5)
    _command(v, MavCmd.COMPONENT_ARM_DISARM, 1.0)
    _command(v, MavCmd.NAV_TAKEOFF)
    run(12.0)
    z = v.snapshot().pos_ned_m[2]
    stream[0] = TrajectorySetpoint(position_ned_m=(0.0, 0.0, z))
    run(0.5)
    main_mode, sub = decode_custom_mode(custom_mode(NavState.OFFBOARD))
    _command(v, MavCmd.DO_SET_MODE, 1 | 128, main_mode, sub)
    stream[0] = TrajectorySetpoint(position_ned_m=(10.0, 0.0, z))
    run(8.0)
    main_mode, sub = decode_custom_mode(custom_mode(NavState.AUTO_LOITER))
    _command(v, MavCmd.DO_SET_MODE, 1 | 128, main_mode, sub)
    stream[0] = None
    _command(v, MavCmd.NAV_LAND)
    run(13.0)


def core_speed() -> tuple[float, float]:
    """(simulated s per CPU s, simulated s) of the manoeuvre without I/O."""
    v = Vehicle()
    cpu = time.process_time()
    manoeuvre(v)
    cpu = time.process_time() - cpu
    return v.time_us / 1e6 / cpu, v.time_us / 1e6


def core_speed_with_io() -> float:
    """Simulated s per CPU s of the same manoeuvre with a node doing its MAVLink I/O after every step (default
    streams on both links, sent to a socket nobody reads; a link is read when the runners' socket watch says so)."""
    from sitl_emu.runtime.runner import SocketWatch
    from sitl_emu.testing.sim import Sim

    with Sim() as sim:
        node = sim.nodes[0]
        v = node.vehicle
        look = SocketWatch(sim.nodes).ready  # as the runners do: one look at the sockets per tick

        def io() -> None:
            ready = look()
            node.step_io(v.time_us, ready.get(0, 0) if ready else 0)

        cpu = time.process_time()
        manoeuvre(v, io)
        cpu = time.process_time() - cpu
        return v.time_us / 1e6 / cpu
