"""The one tick loop: vehicles stepped on a shared simulated timeline, each node's I/O after its tick.

Every runner advances vehicles through this: the real-time runner and the swarm (runtime/runner.py, swarm.py, which
pace it on the wall clock) and the lockstep `Sim` (testing/sim.py, which advances it when asked). Rules:
- tick k of every vehicle runs before tick k+1 of any, so vehicles stay within one tick of each other;
- after the physics of a tick, every node that stepped does its I/O (streams keep their rates, commands are
  answered at the tick they arrive); one look at the sockets per tick says which nodes have datagrams waiting;
- a vehicle that reboots (its own time restarts at 0) keeps its place on the timeline, which never goes back.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Protocol

Ready = dict[int, int]  # node index -> bit set of its links with datagrams waiting (runner.SocketWatch)


class TickVehicle(Protocol):
    """What the tick loop asks of a vehicle (sitl_emu.vehicle.vehicle.Vehicle)."""

    @property
    def dt_us(self) -> int: ...

    @property
    def time_us(self) -> int: ...

    def step(self) -> None: ...


class TickNode(Protocol):
    """What the tick loop asks of a node (runtime/node.py VehicleNode): its vehicle, and its I/O after a tick."""

    @property
    def vehicle(self) -> TickVehicle: ...

    def step_io(self, now_us: int, readable: int) -> object: ...


class Timeline:
    """Simulated time shared by `nodes`, in µs."""

    def __init__(self, nodes: Sequence[TickNode], start_us: int = 0) -> None:
        self.nodes = list(nodes)
        self.time_us = start_us
        self.steps = 0  # vehicle ticks run, all vehicles together
        self.dt_us = int(self.nodes[0].vehicle.dt_us) if self.nodes else 4000
        self._offsets_us = [start_us - int(node.vehicle.time_us) for node in self.nodes]  # timeline - vehicle time

    def advance_to(self, target_us: int, look: Callable[[], Ready], ready: Ready | None = None) -> bool:
        """Run every tick due by `target_us`; `ready` (what the caller's wake-up saw) serves the first tick, later
        ticks `look()` again. True if any vehicle stepped."""
        stepped = False
        while self.time_us + self.dt_us <= target_us:
            due = self._step_physics(target_us)
            if stepped or ready is None:
                ready = look()
            self._step_io(due, ready)
            stepped = stepped or bool(due)
            self.time_us += self.dt_us
        return stepped

    def answer(self, ready: Ready) -> None:
        """Between ticks (woken by a datagram): let the nodes with data read and answer it now."""
        for index, readable in ready.items():
            node = self.nodes[index]
            node.step_io(node.vehicle.time_us, readable)

    def _step_physics(self, target_us: int) -> list[int]:
        """One tick of every vehicle whose next tick is due by `target_us`; the indices of those that stepped."""
        due = []
        for index, node in enumerate(self.nodes):
            vehicle = node.vehicle
            before_us = vehicle.time_us
            if before_us + self._offsets_us[index] + vehicle.dt_us > target_us:
                continue
            vehicle.step()
            if vehicle.time_us < before_us:  # rebooted: its clock restarts at 0, its place on the timeline stays
                self._offsets_us[index] += before_us
            due.append(index)
        self.steps += len(due)
        return due

    def _step_io(self, due: list[int], ready: Ready) -> None:
        for index in due:
            node = self.nodes[index]
            node.step_io(node.vehicle.time_us, ready.get(index, 0) if ready else 0)
