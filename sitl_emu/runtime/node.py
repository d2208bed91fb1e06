"""A vehicle on the wire: one Vehicle and its two MAVLink links (API/onboard and GCS/normal), steppable by any runner.

The node holds no clock and never sleeps. A runner advances the vehicle and calls `step_io(now_us)`, which reads
what arrived (non-blocking, bounded) and sends what is due at `now_us` of simulated time.
Ports follow PX4 SITL (ROMFS/px4fmu_common/init.d-posix/px4-rc.mavlink, reference 1.1): for instance i the API link
listens on 14557+i (the project's default; PX4 today uses 14580+i) and sends to 14540+i, the GCS link listens on
18570+i and sends to 14550 (not offset, so one QGC sees every vehicle).
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any, Final, Protocol

from sitl_emu.mavlink.context import LinkVehicle
from sitl_emu.mavlink.endpoint import Endpoint, load_handler_classes
from sitl_emu.mavlink.link import Address, UdpLink
from sitl_emu.mavlink.signing import MavlinkSigning
from sitl_emu.mavlink.telemetry.streams import SharedBuilds, StreamMode
from sitl_emu.runtime.timeline import TickVehicle
from sitl_emu.types import VehicleSnapshot

if TYPE_CHECKING:
    from sitl_emu.vehicle.vehicle import Vehicle

log = logging.getLogger(__name__)

IO_BUDGET_DATAGRAMS: Final = 200  # per link per step_io: a flood waits in the socket buffer instead of starving physics
# `readable` bits of step_io: which links have datagrams waiting (runners learn it from one SocketWatch look per tick)
READ_API: Final = 1
READ_GCS: Final = 2
READ_BOTH = READ_API | READ_GCS


@dataclass(frozen=True, slots=True)
class LinkSettings:
    bind_host: str = "127.0.0.1"
    api_port: int = 14557
    api_remote: Address | None = ("127.0.0.1", 14540)  # None: no peer until one talks (mavlink/link.py)
    gcs_port: int = 18570
    gcs_remote: Address | None = ("127.0.0.1", 14550)

    def for_instance(self, instance: int) -> LinkSettings:
        """Offset the ports as PX4's `-i N` does (px4-rc.mavlink); the GCS remote stays 14550, and a local port 0
        (let the OS pick) stays 0."""
        if instance == 0:
            return self
        api_remote = self.api_remote
        if api_remote is not None:
            api_remote = (api_remote[0], api_remote[1] + instance if instance <= 9 else 14549)
        return replace(self, api_port=self.api_port + instance if self.api_port else 0,
                       gcs_port=self.gcs_port + instance if self.gcs_port else 0, api_remote=api_remote)


class NodeVehicle(LinkVehicle, TickVehicle, Protocol):
    """A node's vehicle: what its links ask of it, and what the tick loop asks (vehicle/vehicle.py Vehicle; a protocol,
    so that the compiled build takes the tests' stand-ins too)."""


if TYPE_CHECKING:
    def _a_vehicle_is_a_node_vehicle(vehicle: Vehicle) -> NodeVehicle:
        return vehicle  # mypy checks that Vehicle has everything NodeVehicle lists


class VehicleNode:
    """A Vehicle plus its endpoints. `step_io(now_us)` is all a runner calls besides stepping the vehicle."""

    def __init__(self, vehicle: NodeVehicle, settings: LinkSettings = LinkSettings(), epoch_unix_us: int = 0,
                 handler_classes: Sequence[type] | None = None, stream_delay_us: int = 0) -> None:
        """`stream_delay_us`: both links start streaming this long after the first step_io (runtime/swarm.py)."""
        self.vehicle = vehicle
        self.settings = settings
        self.epoch_unix_us = epoch_unix_us
        classes = load_handler_classes() if handler_classes is None else list(handler_classes)
        api_link = UdpLink(settings.bind_host, settings.api_port, settings.api_remote, "API")
        try:
            gcs_link = UdpLink(settings.bind_host, settings.gcs_port, settings.gcs_remote, "GCS")
        except OSError:
            api_link.close()
            raise
        # one signing key for the vehicle's links (mavlink/signing.py); `serve` gives it its key file
        self.signing = MavlinkSigning()
        # link ids (1, 0) are PX4 SITL's mavlink instances: the GCS link starts first (px4-rc.mavlink)
        # a message both links send in a tick is built once (telemetry/streams.py SharedBuilds)
        self.shared = SharedBuilds()
        self.api = Endpoint("api", api_link, self, StreamMode.ONBOARD, classes, stream_delay_us, 1, self.shared)
        self.gcs = Endpoint("gcs", gcs_link, self, StreamMode.NORMAL, classes, stream_delay_us, 0, self.shared)
        self.endpoints: tuple[Endpoint, ...] = (self.api, self.gcs)
        self._event_seq = -1
        self._snapshot: VehicleSnapshot | None = None
        self._snapshot_time_us = -1
        self._last_now_us = -1
        self.io_budget = IO_BUDGET_DATAGRAMS  # datagrams read per link per step_io (the swarm runner lowers it)
        # called with now_us at the start of every step_io, e.g. the flight logger (sitl_emu/log/flight_log.py)
        self.tick_hooks: list[Callable[[int], None]] = []

    @property
    def sysid(self) -> int:
        return int(self.vehicle.sysid)

    def describe(self) -> str:
        """Where each link listens and sends, e.g. for the CLI's one line."""
        parts = []
        for ep, label in ((self.api, "API"), (self.gcs, "GCS")):
            (lh, lp), remote = ep.link.local_address, ep.link.remote
            to = f"sends to {remote[0]}:{remote[1]}" if remote is not None else "sends nothing until a peer talks"
            parts.append(f"{label} listens on {lh}:{lp}, {to}")
        return "; ".join(parts)

    def filenos(self) -> list[int]:
        """The sockets' descriptors, API link first (the order of the READ_API, READ_GCS bits)."""
        return [ep.link.fileno() for ep in self.endpoints]

    # --- the one call a runner makes -----------------------------------------------------------------------------
    def step_io(self, now_us: int, readable: int = READ_BOTH) -> int:
        """Handle what arrived, then send what is due at `now_us`. Returns the number of datagrams read.

        `readable` (READ_API | READ_GCS bits) names the links to read. A runner that watches the sockets passes the
        links that have data waiting, so an idle link costs no recvfrom; by default both are read. Skipping a link
        with nothing waiting changes nothing else: emit() sets the endpoint's time as poll() would have.
        Called every tick for every vehicle, so it is written flat (no loops over the two endpoints).
        """
        if now_us < self._last_now_us:  # the vehicle rebooted (time starts again at 0): restart the schedules
            for ep in self.endpoints:
                ep.restart()
        self._last_now_us = now_us
        if self.tick_hooks:
            for hook in self.tick_hooks:
                hook(now_us)
        received = 0
        if readable:
            if readable & READ_API:
                received = self.api.poll(now_us, self.io_budget)
            if readable & READ_GCS:
                received += self.gcs.poll(now_us, self.io_budget)
        self.shared.active = self.api.link.remote is not None and self.gcs.link.remote is not None
        events = self.vehicle.events_after(self._event_seq)
        if events:
            self._event_seq = events[-1].seq
        self.api.emit(now_us, events)
        self.gcs.emit(now_us, events)
        return received

    # --- services for the endpoints ------------------------------------------------------------------------------
    def snapshot(self) -> VehicleSnapshot:
        """The vehicle's snapshot, taken at most once per simulated instant unless an input changed it."""
        t = self.vehicle.time_us
        if self._snapshot is None or t != self._snapshot_time_us:
            self._snapshot = self.vehicle.snapshot()
            self._snapshot_time_us = t
        return self._snapshot

    def invalidate_snapshot(self) -> None:
        self._snapshot = None

    def broadcast(self, msg: Any) -> None:
        for ep in self.endpoints:
            ep.send(msg)

    def forward(self, msg: Any, origin: Endpoint, target_system: int, target_component: int) -> None:
        """Pass a received message to the other links that should see it (Mavlink::forward_message)."""
        for ep in self.endpoints:
            if ep is origin:
                continue
            if target_system == 0 or (target_system, target_component) in ep.seen_components:
                ep.pass_message(msg)

    def route_ack(self, command: int, result: int, target_system: int, target_component: int) -> None:
        """COMMAND_ACK on every link where the commanding component has been heard (mavlink_main.cpp ~l.2996)."""
        for ep in self.endpoints:
            if (target_system, target_component) in ep.seen_components:
                ep.send(ep.encoder.command_ack_encode(command, result, 0, 0, target_system, target_component))

    def close(self) -> None:
        for ep in self.endpoints:
            ep.close()
