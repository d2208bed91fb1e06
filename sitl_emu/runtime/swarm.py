"""Many vehicles in one process: N nodes with PX4's multi-vehicle numbering, and a runner that keeps them on time.

Instance i (0-based, after `first_instance`) gets sysid 1 + i and every port offset by i, as PX4's `px4 -i N` does
(ROMFS/px4fmu_common/init.d-posix/px4-rc.mavlink, reference 1.1/1.3; LinkSettings.for_instance), and its home
`spacing_m` further east than the previous one so the vehicles do not start on top of each other (PX4's
Tools/simulation/gazebo-classic/sitl_multiple_run.sh spawns instance N at 3 m x N). Each vehicle keeps its own local
frame with its own home as origin, as each PX4 instance has its own EKF origin.

`SwarmRunner` keeps all vehicles on one simulated timeline, tick by tick, and lets each node read at most `io_budget`
datagrams per link per tick: a flood on one vehicle's port costs a bounded time per tick and never holds back the
physics of the others (the rest of the flood waits in that vehicle's own socket buffer).
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable, Sequence

from sitl_emu.geo import SIH_HOME, GeoRef, ned_to_global
from sitl_emu.runtime.node import LinkSettings, NodeVehicle, VehicleNode
from sitl_emu.runtime.runner import RealTimeRunner

log = logging.getLogger(__name__)

DEFAULT_HOME = SIH_HOME  # Vehicle's default home (PX4 SIH default, Zurich)
DEFAULT_SPACING_M = 3.0  # gazebo-classic sitl_multiple_run.sh: instance N spawned at 3*N m
# Vehicle i of a swarm starts streaming i ticks after the first (wrapping at 1 s), as PX4 instances started one after
# another are out of phase. In phase, every vehicle's 1 Hz messages would go out in the same tick: with 64 vehicles
# that tick took about 40 ms, late by ten ticks (measured with bench/scale.py).
STREAM_STAGGER_US = 4000
SWARM_IO_BUDGET = 20  # datagrams read per link per tick (4 ms of simulated time) in the swarm runner

VehicleFactory = Callable[[int, tuple[float, float, float]], NodeVehicle]  # (instance, home) -> a Vehicle


def instance_home(home: tuple[float, float, float], index: int, spacing_m: float = DEFAULT_SPACING_M
                  ) -> tuple[float, float, float]:
    """Home of the `index`-th vehicle of a swarm: `index * spacing_m` east of `home` (lat_deg, lon_deg, alt_m)."""
    if index == 0:
        return home
    return ned_to_global(GeoRef(*home), (0.0, index * spacing_m, 0.0))


def build_nodes(count: int, settings: LinkSettings, make_vehicle: VehicleFactory, *, first_instance: int = 0,
                home: tuple[float, float, float] = DEFAULT_HOME, spacing_m: float = DEFAULT_SPACING_M,
                epoch_unix_us: int = 0, handler_classes: Sequence[type] | None = None,
                handlers_for: Callable[[int], Sequence[type]] | None = None) -> list[VehicleNode]:
    """`count` nodes for instances first_instance.., ports offset per instance; closes them all if one fails.

    `handlers_for(instance)`, if given, gives each node its own protocol handlers (e.g. its own log directory).
    """
    if count < 1:
        raise ValueError("count must be at least 1")
    nodes: list[VehicleNode] = []
    try:
        for i in range(count):
            instance = first_instance + i
            vehicle = make_vehicle(instance, instance_home(home, i, spacing_m))
            classes = handlers_for(instance) if handlers_for is not None else handler_classes
            nodes.append(VehicleNode(vehicle, settings.for_instance(instance), epoch_unix_us, classes,
                                     stream_delay_us(i)))
    except BaseException:
        for node in nodes:
            node.close()
        raise
    return nodes


def stream_delay_us(index: int) -> int:
    """How long after the first tick the `index`-th vehicle of a swarm starts its streams."""
    return index * STREAM_STAGGER_US % 1_000_000


class SwarmRunner(RealTimeRunner):
    """The real-time runner for many nodes (the tick loop is runtime/timeline.py's, as for one vehicle): reads per
    node are capped at `io_budget` datagrams per link per tick, so a flood costs that node a bounded time and the
    other vehicles' physics are not held back; falling behind is warned at most every 10 s.
    """

    def __init__(self, nodes: Sequence[VehicleNode], speed: float = 1.0, hooks: Sequence[Callable[[], None]] = (),
                 io_budget: int = SWARM_IO_BUDGET) -> None:
        super().__init__(nodes, speed, hooks)
        for node in self.nodes:
            node.io_budget = io_budget
        self._last_warning_s = -math.inf

    def _warn_lag(self, lag_us: int) -> None:
        now = time.monotonic()
        if now - self._last_warning_s > 10.0:
            self._last_warning_s = now
            log.warning("%d vehicles fell %.1f s behind real time x%g; dropping the lost time (too many vehicles "
                        "or too high a speed for this CPU)", len(self.nodes), lag_us / 1e6, self.speed)
