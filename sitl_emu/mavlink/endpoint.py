"""One MAVLink link of the vehicle (API/onboard or GCS/normal): parse, dispatch, stream; the context of its handlers.

PX4 runs one `Mavlink` instance per link (src/modules/mavlink/mavlink_main.cpp), each with its own receiver, its own
stream list and rates, its own sequence numbers and its own "GCS seen" bookkeeping; so does this class. It holds no
clock: `poll(now_us)` and `emit(now_us, ...)` are given simulated time by the node.
"""

from __future__ import annotations

import importlib
import logging
import struct
from collections import deque
from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING, Final, Protocol

from pymavlink.dialects.v20 import development as dialect

from px4common.signing_key import KEY_LEN
from sitl_emu.mavlink.context import EndpointStats, LinkVehicle, NodeView, VehicleNews, vehicle_news
from sitl_emu.mavlink.link import UdpLink
from sitl_emu.mavlink.link_commands import CommandHandler
from sitl_emu.mavlink.receiver import Receiver
from sitl_emu.mavlink.signing import ARMED_TEXT, MavlinkSigning, SetupResult
from sitl_emu.mavlink.telemetry.streams import SharedBuilds, StreamMode, Streams
from sitl_emu.mavlink.wire.fastpack import ENCODER, frame_message
from sitl_emu.mavlink.wire.signing import IFLAG_SIGNED, is_signed
from sitl_emu.px4 import Severity

if TYPE_CHECKING:
    from pymavlink.dialects.v20.development import MAVLink_message

    from sitl_emu.mavlink.context import Handler, OutMessage
    from sitl_emu.types import VehicleEvent

log = logging.getLogger(__name__)

COMPID: Final = 1  # MAV_COMP_ID default (mavlink_params.yaml)
MAVLINK_LOG_QUEUE: Final = 8  # msg/MavlinkLog.msg ORB_QUEUE_LENGTH

# Protocol handlers by other modules, one instance per link (sitl_emu/mavlink/context.py). Missing modules are skipped.
HANDLER_CLASSES: tuple[tuple[str, str], ...] = (
    ("sitl_emu.mavlink.protocols.params", "ParamProtocol"),
    ("sitl_emu.mavlink.protocols.mission", "MissionProtocol"),
    ("sitl_emu.mavlink.protocols.shell", "ShellBridge"),
    ("sitl_emu.mavlink.protocols.ftp", "FtpProtocol"),
    ("sitl_emu.mavlink.protocols.log", "LogProtocol"),
    ("sitl_emu.mavlink.protocols.events", "EventsProtocol"),
)


def load_handler_classes(spec: Iterable[tuple[str, str]] = HANDLER_CLASSES) -> list[type]:
    classes: list[type] = []
    for module_name, class_name in spec:
        try:
            module = importlib.import_module(module_name)
        except ModuleNotFoundError as err:
            if err.name != module_name:
                raise
            log.debug("handler module %s not present", module_name)
            continue
        classes.append(getattr(module, class_name))
    return classes


class NodeServices(NodeView, Protocol):
    """What an endpoint needs from the node that owns it: what its parts use (NodeView) and the links' plumbing."""

    @property
    def vehicle(self) -> LinkVehicle: ...

    @property
    def sysid(self) -> int: ...

    @property
    def signing(self) -> MavlinkSigning: ...

    def broadcast(self, msg: OutMessage) -> None: ...

    def forward(self, msg: MAVLink_message, origin: Endpoint, target_system: int, target_component: int) -> None: ...


class Endpoint:
    """A link endpoint; also the context (sitl_emu/mavlink/context.py) handed to its parts and protocol handlers:
    a LinkContext for the handlers, an EndpointContext for its receiver, command handler and telemetry."""

    GCS_TIMEOUT_US = 2_500_000  # is_gcs_connected(): GCS heartbeat within 2.5 s (mavlink_main.h)

    def __init__(self, name: str, link: UdpLink, node: NodeServices, mode: StreamMode,
                 handler_classes: Sequence[type] = (), stream_delay_us: int = 0, link_id: int = 0,
                 shared: SharedBuilds | None = None) -> None:
        """`shared`: what the vehicle's links build once for all of them in a tick (telemetry/streams.py)."""
        self.link_name = name
        self.link_id = link_id  # PX4's mavlink instance number: the link id of what it signs
        self.link = link
        self.node = node
        self.vehicle: LinkVehicle = node.vehicle  # attributes, not properties: the handlers read these every tick
        self.now_us = 0  # simulated time of the pass under way (poll, emit)
        self.sysid = node.sysid
        self.compid = COMPID
        self.encoder = ENCODER  # builds what this link sends (sitl_emu/mavlink/wire/fastpack.py)
        self.seq = 0  # this link's sequence number: one sequence per link, as PX4's Mavlink instance
        self.signing = node.signing  # the vehicle's MAVLink 2 signing, shared by its links (mavlink/signing.py)
        self._parser = _new_parser()
        self.stats = EndpointStats()
        self.streams = Streams(mode, stream_delay_us, shared)
        self.receiver = Receiver(CommandHandler(self.streams))
        self.seen_components: set[tuple[int, int]] = set()
        self.last_gcs_heartbeat_us: int | None = None
        # mavlink_log messages wait (uORB queue of 8) until a GCS is connected; older than 5 s they are dropped
        self._pending_texts: deque[VehicleEvent] = deque(maxlen=MAVLINK_LOG_QUEUE)
        self._handlers: list[Handler] = [cls() for cls in handler_classes]
        self._tickers = [h for h in self._handlers if getattr(h, "TICKS", True)]  # context.py: TICKS False = idle
        # the handlers ticked at the next emit: one whose tick() says it is idle (False) sleeps until a message
        # arrives on this link (dispatch wakes them all), so idle protocols cost nothing per tick
        self._awake: list[Handler] = list(self._tickers)
        # some handlers also act on news of the vehicle (context.vehicle_news): a change wakes them all
        self._watches_vehicle = any(getattr(h, "WATCHES_VEHICLE", False) for h in self._tickers)
        self._news: VehicleNews | None = None
        self._routes: dict[str, list[Handler]] = {}
        for h in self._handlers:
            for msg_type in h.MESSAGES:
                self._routes.setdefault(msg_type, []).append(h)

    # --- LinkContext (also its attributes vehicle and now_us) -------------------------------------------------------
    def send(self, msg: OutMessage) -> None:
        """One message, one datagram (PX4's send_start/send_finish); the frame is the one pymavlink would pack.
        Nothing at all while the link has no peer (link.py: a Sim's link nobody has talked to yet)."""
        if self.link.remote is None:
            return
        try:
            if self.signing.key is None:
                data = frame_message(msg, self.seq, self.sysid, COMPID)
            else:  # with a key, PX4 signs everything it sends
                data = self.signing.sign(frame_message(msg, self.seq, self.sysid, COMPID, IFLAG_SIGNED),
                                         self.link_id, self.node.epoch_unix_us + self.now_us)
        except (struct.error, ValueError, TypeError, OverflowError) as err:  # a field out of its wire range
            self.stats.tx_pack_errors += 1
            if self.stats.tx_pack_errors == 1:
                log.error("%s link: cannot send %s: %s", self.link_name, msg.get_type(), err)
            return
        self.link.send(data)
        self.seq = (self.seq + 1) % 256
        stats = self.stats
        stats.tx_messages += 1
        stats.tx_bytes += len(data)

    def broadcast(self, msg: OutMessage) -> None:
        self.node.broadcast(msg)

    # --- receive -------------------------------------------------------------------------------------------------
    def poll(self, now_us: int, max_datagrams: int = 256) -> int:
        """Read and handle what has arrived; returns the number of datagrams read."""
        self.now_us = now_us
        datagrams = self.link.receive(max_datagrams)
        for data in datagrams:
            self.stats.rx_bytes += len(data)
            for msg in self._parse(data):
                self.dispatch(msg)
        return len(datagrams)

    def dispatch(self, msg: MAVLink_message) -> None:
        msg_type = msg.get_type()
        if msg_type == "BAD_DATA":
            self.stats.rx_parse_errors += 1
            return
        src = (msg.get_srcSystem(), msg.get_srcComponent())
        if src == (self.sysid, self.compid):  # our own messages looped back (PX4 ignores these)
            self.stats.rx_own_echo += 1
            return
        if self.signing.key is not None and not self.signing.accept(msg.get_msgbuf(), msg.get_msgId(), *src):
            self.stats.rx_signing_rejected += 1  # the MAVLink parser drops it: MAVLINK_FRAMING_BAD_SIGNATURE
            return
        if msg_type == "SETUP_SIGNING":  # handled and consumed by the mavlink module (check_for_signing)
            self._setup_signing(msg)
            return
        self.stats.rx_messages += 1
        self.seen_components.add(src)
        self.wake_handlers()
        try:
            self.receiver.handle(msg, self)
            for handler in self._routes.get(msg_type, ()):
                handler.handle(msg, self)
        except Exception as err:  # a bad message must never stop the vehicle
            self.stats.handler_errors += 1
            log.error("%s link: error handling %s: %r", self.link_name, msg_type, err,
                      exc_info=log.isEnabledFor(logging.DEBUG))
        self._forward(msg)

    def _setup_signing(self, msg: MAVLink_message) -> None:
        key = bytes(getattr(msg, "secret_key", b"")).ljust(KEY_LEN, b"\0")[:KEY_LEN]
        timestamp = int(getattr(msg, "initial_timestamp", 0))
        result = self.signing.setup(key, timestamp, is_signed(msg.get_msgbuf()), self.node.snapshot().armed,
                                    self.node.epoch_unix_us + self.now_us)
        log.info("%s link: SETUP_SIGNING: %s", self.link_name, result.value)
        if result is SetupResult.REJECTED_ARMED:
            self.vehicle.report(Severity.CRITICAL, "mavlink", ARMED_TEXT, is_event=False)

    def _forward(self, msg: MAVLink_message) -> None:
        """Mavlink::forward_message (both SITL links run with -f): pass on what is not only for us, unchanged.

        A message with target (our sysid, our compid) stays here; others go to every other link, if broadcast
        (target_system 0 or no target) or if that link has heard the target component. Heartbeats are forwarded too
        (MAV_HB_FORW_EN defaults to 1).
        """
        target_system = getattr(msg, "target_system", 0)
        target_component = getattr(msg, "target_component", 0)
        if target_system == self.sysid and target_component == self.compid:
            return
        self.node.forward(msg, self, target_system, target_component)

    def pass_message(self, msg: MAVLink_message) -> None:
        """Send a received message on as it is (its own sysid, compid, sequence and checksum)."""
        if self.link.remote is None:
            return
        data = bytes(msg.get_msgbuf())
        self.stats.tx_forwarded += 1
        self.stats.tx_bytes += len(data)
        self.link.send(data)

    def gcs_connected(self) -> bool:
        last = self.last_gcs_heartbeat_us
        return last is not None and self.now_us - last <= self.GCS_TIMEOUT_US

    def _parse(self, data: bytes) -> list[MAVLink_message]:
        """Frames in one datagram. A frame cut short at the datagram's end is dropped, so it cannot swallow the
        start of the next datagram (senders put whole frames in each datagram)."""
        try:
            msgs = self._parser.parse_buffer(data) or []
        except Exception as err:  # pymavlink raises on some malformed input even in robust mode
            self.stats.rx_parse_errors += 1
            log.debug("%s link: parse error %s", self.link_name, err)
            self._parser = _new_parser()
            return []
        if self._parser.buf_len() > 0:
            self.stats.rx_parse_errors += 1
            self._parser = _new_parser()
        return msgs

    # --- transmit ------------------------------------------------------------------------------------------------
    def emit(self, now_us: int, events: Sequence[VehicleEvent]) -> None:
        """Send what is due at `now_us`: heartbeat, streams, status texts, then let handlers stream.

        A link with no peer (link.py) builds no stream at all: its schedule waits, and the first pass after a peer
        talks sends the heartbeat and every stream at once, as a link just started would."""
        # Called every tick on every link: when nothing is due and nothing happened this costs a few comparisons.
        self.now_us = now_us
        if now_us >= self.streams.next_due_us and self.link.remote is not None:
            self.streams.emit_due(self, self.node.snapshot)
        if events:
            self._pending_texts.extend(e for e in events if e.statustext)
        if self._pending_texts and self.gcs_connected():  # texts wait for a GCS
            self.streams.send_statustexts(self, list(self._pending_texts))
            self._pending_texts.clear()
        if self._watches_vehicle:  # news of the vehicle since the last emit wakes the handlers
            news = vehicle_news(self.vehicle)
            if news != self._news:
                self._news = news
                self.wake_handlers()
        if self._awake:
            self._tick_handlers()

    def _tick_handlers(self) -> None:
        """Tick the awake handlers in their table order; those that say they are idle sleep until woken."""
        idle: list[Handler] = []
        for handler in self._awake:
            try:
                if handler.tick(self) is False:
                    idle.append(handler)  # until its next message
            except Exception as err:
                self.stats.handler_errors += 1
                log.error("%s link: error in %s.tick: %r", self.link_name, type(handler).__name__, err,
                          exc_info=log.isEnabledFor(logging.DEBUG))
        if idle:
            self._awake = [handler for handler in self._awake if handler not in idle]

    def wake_handlers(self) -> None:
        """Tick every handler again from the next emit (a message arrived: any of them may have work now)."""
        if len(self._awake) != len(self._tickers):
            self._awake = list(self._tickers)

    def restart(self) -> None:
        """After a vehicle reboot: streams restart from time 0 at their current rates; the GCS must be heard again."""
        self.wake_handlers()
        self.streams.restart()
        self.last_gcs_heartbeat_us = None
        self._pending_texts.clear()

    def close(self) -> None:
        self.link.close()


def _new_parser() -> dialect.MAVLink:
    parser = dialect.MAVLink(None, srcSystem=0, srcComponent=0)
    parser.robust_parsing = True
    return parser
