"""The runners' own cost, apart from the vehicle: nodes whose vehicle is a stub (time advances, nothing else happens).

The stub hands telemetry a fixed snapshot of a hovering vehicle, so the links send what they send in a hover: what is
measured is the runner (wake-ups, socket watch), the node (step_io) and the MAVLink endpoints (streams, handlers,
packing, sendto), without physics or controllers. Telemetry goes to a socket nobody reads, as in bench/scale.py.
"""

from __future__ import annotations

import logging
import math
import socket
import time
from collections.abc import Sequence
from typing import Any

from sitl_emu.events.catalogue import Px4Event
from sitl_emu.mavlink.telemetry.streams import BUILDERS
from sitl_emu.navigator.mission_store import MissionStore
from sitl_emu.px4 import MavCmd
from sitl_emu.runtime.node import LinkSettings, VehicleNode
from sitl_emu.runtime.runner import RealTimeRunner
from sitl_emu.runtime.swarm import SwarmRunner
from sitl_emu.types import VehicleCommand, VehicleEvent, VehicleSnapshot
from sitl_emu.vehicle.vehicle import Vehicle


class StubVehicle:
    """What a node needs of a Vehicle: time moves by dt_us per step; snapshot, params and events never change."""

    def __init__(self, snapshot: VehicleSnapshot, params: Any, store: MissionStore, sysid: int = 1,
                 dt_us: int = 4000) -> None:
        self.time_us = 0
        self.dt_us = dt_us
        self.sysid = sysid
        self.params = params
        self._snapshot = snapshot
        self._store = store

    def step(self) -> None:
        self.time_us += self.dt_us

    def snapshot(self) -> VehicleSnapshot:
        return self._snapshot

    def events_after(self, seq: int) -> list[VehicleEvent]:
        return []

    def px4_events_after(self, seq: int) -> list[tuple[int, Px4Event]]:
        return []

    def mission_store(self) -> MissionStore:
        return self._store


def hover_snapshot() -> tuple[VehicleSnapshot, Any, MissionStore]:
    """A real vehicle's snapshot 8 s after NAV_TAKEOFF (hovering in Hold), its parameters and its mission store."""
    v = Vehicle()
    v.run_until(2_100_000)
    nan = math.nan
    v.handle_command(VehicleCommand(MavCmd.COMPONENT_ARM_DISARM, (1.0,) + (nan,) * 6))
    v.handle_command(VehicleCommand(MavCmd.NAV_TAKEOFF, (nan,) * 7))
    v.run_until(10_100_000)
    return v.snapshot(), v.params, v.mission_store()


def stub_nodes(count: int, streams: bool = True) -> tuple[list[VehicleNode], socket.socket]:
    """`count` stub nodes on free loopback ports sending to one sink socket; `streams=False` stops every stream
    but HEARTBEAT (SET_MESSAGE_INTERVAL -1), leaving the bare runner and node."""
    snapshot, params, store = hover_snapshot()
    sink = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sink.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    sink.bind(("127.0.0.1", 0))
    settings = LinkSettings("127.0.0.1", 0, sink.getsockname(), 0, sink.getsockname())
    nodes = [VehicleNode(StubVehicle(snapshot, params, store, i + 1), settings) for i in range(count)]
    if not streams:
        for node in nodes:
            for ep in node.endpoints:
                for msg_id in BUILDERS:
                    ep.streams.set_interval(msg_id, -1)
    return nodes, sink


def _close(nodes: Sequence[VehicleNode], sink: socket.socket) -> None:
    for node in nodes:
        node.close()
    sink.close()


def real_time_share(seconds: float, min_wake_s: float = 0.0, streams: bool = True) -> tuple[float, float]:
    """One stub node run by RealTimeRunner at real time: (% of one core, CPU µs per tick)."""
    nodes, sink = stub_nodes(1, streams)
    try:
        runner = RealTimeRunner(nodes, speed=1.0)
        runner.min_wake_s = min_wake_s
        cpu, wall = time.process_time(), time.monotonic()
        runner.run(duration_s=seconds)
        cpu, wall = time.process_time() - cpu, time.monotonic() - wall
    finally:
        _close(nodes, sink)
    return 100.0 * cpu / wall, cpu / max(runner.steps, 1) * 1e6


def swarm_tick_cost(count: int, sim_seconds: float, streams: bool = True) -> float:
    """CPU µs per vehicle-tick of SwarmRunner with `count` stub nodes, as fast as it goes (no sleeping)."""
    nodes, sink = stub_nodes(count, streams)
    swarm_log = logging.getLogger("sitl_emu.runtime.swarm")
    level = swarm_log.level
    swarm_log.setLevel(logging.ERROR)  # it falls behind on purpose: no lag warnings
    try:
        runner = SwarmRunner(nodes, speed=1e6)
        runner.run(duration_s=0.2)  # warm up
        steps0, cpu = runner.steps, time.process_time()
        runner.run(duration_s=sim_seconds)
        cpu = time.process_time() - cpu
        return cpu / max(runner.steps - steps0, 1) * 1e6
    finally:
        swarm_log.setLevel(level)
        _close(nodes, sink)
