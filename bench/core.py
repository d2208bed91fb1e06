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
CLIENT_POLL_US = 10_000  # how often the scripted client reads (testing/client.py POLL_S)


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
            if after_step is not None:
                v.step()
                after_step()
            else:  # nothing between the steps up to the next setpoint: the vehicle's own loop steps there
                v.run_until(end if sp is None else min(end, next_us[0]))

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


class _VehicleClock:
    """The vehicle's simulated seconds, for the scripted client (it never sleeps here: the manoeuvre steps)."""

    def __init__(self, v: Vehicle) -> None:
        self._v = v

    def now(self) -> float:
        return self._v.time_us / 1e6

    def sleep(self, seconds: float) -> None:
        raise RuntimeError("the manoeuvre steps the vehicle; the client only reads")


def core_speed_with_io() -> float:
    """Simulated s per CPU s of the same manoeuvre with a node doing its MAVLink I/O after every step, as in a
    campaign case: the API link streams its default set to a scripted client in this process (testing/client.py,
    which talks first and reads every CLIENT_POLL_US; its CPU counts), the GCS link has no peer and builds nothing.
    A link is read when the runners' socket watch says so."""
    return io_run()[0]


def io_run() -> tuple[float, float, int]:
    """core_speed_with_io's run: (simulated s per CPU s, simulated s, datagrams the API link sent)."""
    from sitl_emu.runtime.runner import SocketWatch
    from sitl_emu.testing.client import FlightClient
    from sitl_emu.testing.sim import Sim

    with Sim() as sim:
        node = sim.nodes[0]
        v = node.vehicle
        client = FlightClient(sim.ports(0).api, _VehicleClock(v))
        look = SocketWatch(sim.nodes).ready  # as the runners do: one look at the sockets per tick
        next_poll_us = [0]

        def io() -> None:
            ready = look()
            node.step_io(v.time_us, ready.get(0, 0) if ready else 0)
            if v.time_us >= next_poll_us[0]:
                client.pump()
                next_poll_us[0] = v.time_us + CLIENT_POLL_US

        cpu = time.process_time()
        manoeuvre(v, io)
        cpu = time.process_time() - cpu
        client.close()
        if client.seen.pos_ned_m is None:
            raise RuntimeError("the scripted client heard no position: the API link did not stream")
        return v.time_us / 1e6 / cpu, v.time_us / 1e6, node.api.link.stats.tx_datagrams
