"""The contracts inside a link: what an endpoint offers the protocol handlers and its own parts.

An endpoint (one UDP link: API or GCS, sitl_emu/mavlink/endpoint.py) owns its sequence number, the latched peer and
the stream scheduler; all it sends is built with the one encoder (ctx.encoder: wire/fastpack.py). For each received
message whose type a handler lists in MESSAGES, it calls handler.handle(msg, ctx); once per main-loop iteration it
calls handler.tick(ctx) so handlers can stream (parameter lists, shell output). Handlers never touch sockets or
clocks: they read ctx.now_us and call ctx.send().

- LinkContext: what a plugged-in protocol handler (params, mission, shell) may use.
- EndpointContext: LinkContext plus what the endpoint's own parts use (receiver, command handler, telemetry
  builders): the node's snapshot and ACK routing, the GCS heartbeat bookkeeping.
Tests implement LinkContext in memory (tests/handler_ctx.py); Endpoint implements both.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar, Protocol

if TYPE_CHECKING:
    from typing import TypeAlias

    from pymavlink.dialects.v20.development import MAVLink_message

    from sitl_emu.events.definition import Px4Event
    from sitl_emu.mavlink.wire.encoding import MessageEncoder
    from sitl_emu.mavlink.wire.fastpack import Packed
    from sitl_emu.navigator.mission_store import MissionStore
    from sitl_emu.params import ParamRegistry
    from sitl_emu.px4 import Severity
    from sitl_emu.types import (
        AttitudeSetpoint,
        CommandAck,
        FollowTargetSample,
        GroundTruth,
        ManualControlSetpoint,
        OffboardControlMode,
        TrajectorySetpoint,
        VehicleCommand,
        VehicleEvent,
        VehicleSnapshot,
    )
    from sitl_emu.vehicle.vehicle import Vehicle

    # What a link sends: a message built with ctx.encoder (wire/fastpack.py)
    OutMessage: TypeAlias = Packed


@dataclass(slots=True)
class EndpointStats:
    """One link's counters (PX4's telemetry_status): what LINK_NODE_STATUS reports, and the endpoint's own errors."""

    rx_messages: int = 0
    rx_bytes: int = 0
    rx_parse_errors: int = 0
    rx_own_echo: int = 0
    handler_errors: int = 0
    tx_messages: int = 0
    tx_bytes: int = 0
    tx_pack_errors: int = 0
    tx_forwarded: int = 0
    rx_signing_rejected: int = 0  # unsigned, wrongly signed, replayed or stale, while signing is on
    # the byte counts at the last rate sample (link_rates)
    _rate_time_us: int = -1
    _rate_tx_bytes: int = 0
    _rate_rx_bytes: int = 0
    _tx_rate: int = 0
    _rx_rate: int = 0

    def link_rates(self, now_us: int) -> tuple[int, int]:
        """(tx, rx) bytes per second since the previous sample at least half a second ago (the first call: 0, 0)."""
        dt_us = now_us - self._rate_time_us
        if self._rate_time_us < 0 or dt_us < 0:
            self._rate_time_us, self._rate_tx_bytes, self._rate_rx_bytes = now_us, self.tx_bytes, self.rx_bytes
        elif dt_us >= 500_000:
            self._tx_rate = (self.tx_bytes - self._rate_tx_bytes) * 1_000_000 // dt_us
            self._rx_rate = (self.rx_bytes - self._rate_rx_bytes) * 1_000_000 // dt_us
            self._rate_time_us, self._rate_tx_bytes, self._rate_rx_bytes = now_us, self.tx_bytes, self.rx_bytes
        return self._tx_rate & 0xFFFFFFFF, self._rx_rate & 0xFFFFFFFF


class LinkVehicle(Protocol):
    """The vehicle as the links see it: all that the endpoint, its parts and the protocol handlers ask of it.

    vehicle/vehicle.py's Vehicle is one (checked below); the link's unit tests drive it with a recording stand-in
    (tests/support/fakes.py). Typed as this protocol, the compiled build does not insist on the Vehicle class.
    """

    sysid: int
    params: ParamRegistry

    @property
    def time_us(self) -> int: ...

    def snapshot(self) -> VehicleSnapshot: ...

    def ground_truth(self) -> GroundTruth | None:
        """The simulator's true state (HIL_STATE_QUATERNION); None where no simulator stands behind the vehicle."""
        ...

    def events_after(self, seq: int) -> list[VehicleEvent]: ...

    def px4_events_after(self, seq: int) -> list[tuple[int, Px4Event]]:
        """PX4's events (sitl_emu/events) after `seq`, each with its own seq, in the order sent."""
        ...

    def report(self, severity: Severity, module: str, text: str, is_event: bool = True) -> None: ...

    def handle_command(self, cmd: VehicleCommand) -> CommandAck | None: ...

    def offboard_input(self, mode: OffboardControlMode, trajectory: TrajectorySetpoint | None = None,
                       attitude: AttitudeSetpoint | None = None) -> None: ...

    def manual_control_input(self, setpoint: ManualControlSetpoint) -> None: ...

    def follow_target_input(self, sample: FollowTargetSample) -> None: ...

    def gcs_heartbeat(self) -> None: ...

    def mission_store(self) -> MissionStore: ...


if TYPE_CHECKING:
    def _a_vehicle_is_a_link_vehicle(vehicle: Vehicle) -> LinkVehicle:
        return vehicle  # mypy checks that Vehicle has all of LinkVehicle


class LinkContext(Protocol):
    link_name: str  # "api" or "gcs"
    sysid: int
    compid: int

    @property
    def encoder(self) -> MessageEncoder:
        """Builds what the link sends, with pymavlink's calls: ctx.send(ctx.encoder.param_value_encode(...))."""
        ...

    @property
    def vehicle(self) -> LinkVehicle: ...

    @property
    def now_us(self) -> int: ...

    def send(self, msg: OutMessage) -> None:
        """Send on this link, to its latched peer (or its initial remote)."""
        ...

    def broadcast(self, msg: OutMessage) -> None:
        """Send on every link of this vehicle (PX4 re-broadcasts changed parameters)."""
        ...


class NodeView(Protocol):
    """What an endpoint's parts ask of the node that owns the links (sitl_emu/runtime/node.py VehicleNode)."""

    epoch_unix_us: int  # wall time of simulated time 0 (SYSTEM_TIME)

    def snapshot(self) -> VehicleSnapshot: ...

    def invalidate_snapshot(self) -> None:
        """An input changed the vehicle: the next snapshot() must be a fresh one."""
        ...

    def route_ack(self, command: int, result: int, target_system: int, target_component: int) -> None:
        """COMMAND_ACK on every link where the commanding component has been heard."""
        ...


class EndpointContext(LinkContext, Protocol):
    last_gcs_heartbeat_us: int | None  # the receiver sets it on a GCS heartbeat
    stats: EndpointStats  # this link's counters (LINK_NODE_STATUS)

    @property
    def node(self) -> NodeView: ...


class Handler(Protocol):
    MESSAGES: ClassVar[tuple[str, ...]]  # pymavlink type names, e.g. ("PARAM_SET", "PARAM_REQUEST_LIST")
    # Optional: a handler whose tick() never sends may set `TICKS: ClassVar[bool] = False`; the endpoint then does
    # not call it (one call less per link and tick). Absent means True.

    def handle(self, msg: MAVLink_message, ctx: LinkContext) -> None: ...

    # Optional: `WATCHES_VEHICLE: ClassVar[bool] = True` for a handler whose tick() also acts on what vehicle_news()
    # returns (below): an idle one is ticked again when that changes.

    def tick(self, ctx: LinkContext) -> bool | None:
        """Stream, retry, time out. Return False when only a message on this link (or, with WATCHES_VEHICLE, news
        of the vehicle) can give it work again: no transfer under way, no timeout to watch; the endpoint then skips
        it until then. None or True: tick it again next time."""


VehicleNews = tuple[int, int, bool, int]


def vehicle_news(vehicle: LinkVehicle) -> VehicleNews:
    """What protocol handlers act on between messages: the parameters' version (protocols/params.py sends changed
    values, as PX4's parameter_update subscription) and the navigator's mission progress (protocols/mission.py reports
    it, as PX4's mission_result subscription). The version read as its compiled count (params/changes.py)."""
    store = vehicle.mission_store()
    return vehicle.params.changes.value, store.current_seq, store.finished, store.seq_reached
