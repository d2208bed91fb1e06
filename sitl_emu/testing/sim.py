"""In-process Python API for tests: one or more emulated vehicles on loopback UDP, stepped in lockstep.

    with Sim(count=2, params={"MIS_TAKEOFF_ALT": 5}) as sim:
        port = sim.ports(0).api[1]            # a real MAVLink client sends here (and is answered from here)
        client = FlightClient(sim.ports(0).api, sim.clock)    # or pymavlink, MAVSDK (with sim.start()), joyfly
        sim.run_for(3.0)                      # 3 s of simulated time, as fast as the CPU allows

Lockstep: simulated time advances only when the script asks (`run_for`, `run_until`, or `sim.clock.sleep(s)`), in
the vehicles' 4 ms ticks, and every node does its MAVLink I/O after each tick. A client in the same process that
sends a datagram and then sleeps on `sim.clock` is therefore answered at a deterministic simulated instant: the same
script, seed and params give the same trajectory every run. `sim.clock` satisfies joyfly's Clock protocol (now() in
seconds, sleep(seconds)), so a joyfly FlightSession can fly a Sim vehicle in lockstep.

Clients that keep their own wall-clock timers (MAVSDK, MAVROS) need `sim.start(speed)`, which runs the vehicles in a
background thread at `speed` x real time (the runner of `sitl-emu serve --count`); `stop()` returns to lockstep.

Until a client talks to it, a link has no peer (sitl_emu/mavlink/link.py): nobody could receive its telemetry, so it
builds and sends none, and parallel tests never see each other's vehicles. The first datagram a link receives makes
its sender the peer for good, as PX4 latches it, and the link streams from then on. Pass `api_remote=("127.0.0.1",
14540)` (or `gcs_remote`) to stream from boot to where PX4 SITL sends instead (the API port + instance), as `serve`.
"""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from sitl_emu.disturbance.estimate import EstimateNoiseSettings
from sitl_emu.disturbance.wind import WindSettings
from sitl_emu.mavlink.link import Address
from sitl_emu.params import default_registry
from sitl_emu.runtime.node import IO_BUDGET_DATAGRAMS, LinkSettings, VehicleNode
from sitl_emu.runtime.runner import SocketWatch
from sitl_emu.runtime.swarm import DEFAULT_HOME, DEFAULT_SPACING_M, SwarmRunner, build_nodes
from sitl_emu.runtime.timeline import Timeline
from sitl_emu.vehicle.vehicle import Vehicle

__all__ = ["LockstepClock", "Sim", "VehiclePorts"]  # a wall clock sped up: px4common.clock.ScaledClock


@dataclass(frozen=True, slots=True)
class VehiclePorts:
    """Where vehicle `index` listens: send to `api` (the offboard/API link) or `gcs` (the GCS link)."""

    index: int
    sysid: int
    api: Address
    gcs: Address


class LockstepClock:
    """Simulated seconds since the Sim started; `sleep` advances the vehicles (joyfly's Clock protocol)."""

    def __init__(self, sim: Sim) -> None:
        self._sim = sim

    def now(self) -> float:
        return self._sim.time_us / 1e6

    def sleep(self, seconds: float) -> None:
        """At least one microsecond for any positive `seconds`: a wait that rounded to 0 us would never end."""
        if seconds > 0:
            self._sim.advance_to(self._sim.time_us + max(1, round(seconds * 1e6)))


class Sim:
    """`count` vehicles (sysids 1..count, homes `spacing_m` apart eastwards) on free loopback ports."""

    def __init__(self, count: int = 1, *, params: Mapping[str, float] | None = None, seed: int = 0,
                 home: tuple[float, float, float] = DEFAULT_HOME, spacing_m: float = DEFAULT_SPACING_M,
                 api_remote: Address | None = None, gcs_remote: Address | None = None,
                 bind_host: str = "127.0.0.1", vehicle_options: Mapping[str, Any] | None = None,
                 wind: WindSettings | None = None,
                 estimate_noise: EstimateNoiseSettings | Mapping[str, float] | None = None,
                 log_dir: str | os.PathLike[str] | None = None) -> None:
        """`log_dir`: write a ULog per flight there (vehicle i > 0 in `<log_dir>-<i>`) and serve them over
        LOG_REQUEST_*, as `sitl-emu serve --log-dir` (sitl_emu/log/); `self.loggers` are the loggers."""
        self._param_values = dict(params or {})
        self._seed = seed
        self._vehicle_options = dict(vehicle_options or {})
        if wind is not None:  # sitl_emu/disturbance/wind.py: WindSettings(5.0, 270.0) or parse_wind("5@270,light")
            self._vehicle_options["wind"] = wind
        if isinstance(estimate_noise, Mapping):  # plain data, as a campaign's options give: {"pos_white_m": 0.3}
            estimate_noise = EstimateNoiseSettings.from_mapping(estimate_noise)
        if estimate_noise is not None:  # sitl_emu/disturbance/estimate.py: white noise and bias walk on the estimate
            self._vehicle_options["estimate_noise"] = estimate_noise
        settings = LinkSettings(bind_host, 0, api_remote, 0, gcs_remote)  # None: no peer until one talks
        handlers_for = None
        if log_dir is not None:
            from sitl_emu.log.serving import handler_classes, instance_log_dir

            def handlers_for(instance: int) -> Sequence[type]:
                return handler_classes(instance_log_dir(log_dir, instance))
        self._vehicles: list[Vehicle] = []  # the nodes' vehicles, as built (a reboot keeps the object)
        self.nodes: list[VehicleNode] = build_nodes(count, settings, self._make_vehicle, home=home,
                                                    spacing_m=spacing_m, epoch_unix_us=int(time.time() * 1e6),
                                                    handlers_for=handlers_for)
        self.loggers: list[Any] = []  # sitl_emu.log.flight_log.FlightLogger, one per vehicle, with log_dir
        if log_dir is not None:
            from sitl_emu.log.serving import attach_logger, instance_log_dir

            self.loggers = [attach_logger(node, instance_log_dir(log_dir, i)) for i, node in enumerate(self.nodes)]
        self._timeline = Timeline(self.nodes)  # the lockstep tick loop (runtime/timeline.py)
        self._watch = SocketWatch(self.nodes)
        self._time_us = 0
        self.clock = LockstepClock(self)
        self._runner: SwarmRunner | None = None
        self._background_start_us = 0
        self._thread: threading.Thread | None = None

    def _make_vehicle(self, instance: int, home: tuple[float, float, float]) -> Vehicle:
        registry = default_registry()
        if "MAV_SYS_ID" in registry:  # rcS: param set MAV_SYS_ID $((px4_instance+1))
            registry.set("MAV_SYS_ID", instance + 1)
        for name, value in self._param_values.items():
            registry.set(name, float(value))
        vehicle = Vehicle(params=registry, home=home, seed=self._seed + instance, sysid=instance + 1,
                          **self._vehicle_options)
        self._vehicles.append(vehicle)
        return vehicle

    # --- what a script reads ---------------------------------------------------------------------------------
    @property
    def vehicles(self) -> list[Vehicle]:
        return list(self._vehicles)

    def vehicle(self, index: int = 0) -> Vehicle:
        return self._vehicles[index]

    def ports(self, index: int = 0) -> VehiclePorts:
        node = self.nodes[index]
        return VehiclePorts(index, node.sysid, _reachable(node.api.link.local_address),
                            _reachable(node.gcs.link.local_address))

    @property
    def time_us(self) -> int:
        """Simulated time since the Sim started (µs); unlike a vehicle's own time it never restarts."""
        if self._runner is not None:
            return self._background_start_us + self._runner.timeline_us
        return self._time_us

    # --- lockstep ----------------------------------------------------------------------------------------------
    def advance_to(self, target_us: int) -> None:
        """Step every vehicle tick by tick up to `target_us` of Sim time, with each node's I/O after its tick."""
        self._require_lockstep()
        self._timeline.advance_to(target_us, self._watch.ready)
        self._time_us = max(self._time_us, target_us)

    def run_for(self, seconds: float) -> None:
        self.advance_to(self._time_us + round(seconds * 1e6))

    def run_until(self, predicate: Callable[[], bool], timeout_s: float, poll_s: float = 0.004) -> bool:
        """Run until `predicate()` holds (checked every `poll_s` of simulated time); False on timeout."""
        end_us = self._time_us + round(timeout_s * 1e6)
        while not predicate():
            if self._time_us >= end_us:
                return False
            self.advance_to(min(end_us, self._time_us + round(poll_s * 1e6)))
        return True

    # --- real time in the background -----------------------------------------------------------------------
    def start(self, speed: float = 1.0) -> None:
        """Run the vehicles at `speed` x wall time in a daemon thread until `stop()`."""
        if self._runner is not None:
            raise RuntimeError("The Sim is already running in the background; call stop() first.")
        self._background_start_us = self._time_us
        self._runner = SwarmRunner(self.nodes, speed=speed, io_budget=IO_BUDGET_DATAGRAMS)
        self._thread = threading.Thread(target=self._runner.run, name="sitl-emu-sim", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        """Stop the background runner; lockstep methods work again from the time reached."""
        if self._runner is None or self._thread is None:
            return
        self._runner.stop()
        self._thread.join(5.0)
        self._time_us = self.time_us
        self._timeline = Timeline(self.nodes, start_us=self._time_us)
        self._runner = None
        self._thread = None

    def _require_lockstep(self) -> None:
        if self._runner is not None:
            raise RuntimeError("The Sim runs in the background (start()); call stop() before stepping it.")

    # --- lifetime ----------------------------------------------------------------------------------------------
    def close(self) -> None:
        self.stop()
        for logger in self.loggers:
            logger.close()
        self._watch.close()
        for node in self.nodes:
            node.close()

    def __enter__(self) -> Sim:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _reachable(address: Address) -> Address:
    host, port = address
    return ("127.0.0.1" if host in ("0.0.0.0", "") else host, port)
