"""Telemetry streams per link: which messages, at which rates, scheduled on simulated time.

Default sets from PX4's configure_streams_to_default() (src/modules/mavlink/mavlink_main.cpp, reference 1.5/1.6),
restricted to messages whose data we have, plus the SITL GCS-link overrides of ROMFS/px4fmu_common/init.d-posix/
px4-rc.mavlink (50 Hz position/attitude). The GCS link's set and rates are those PX4 SIH measurably streams at rest
(../shared/reference/px4-gcs-streams.json), but for CURRENT_EVENT_SEQUENCE (extra_messages.py says why).
HEARTBEAT is always 1 Hz and cannot be changed (mavlink_main.cpp ~l.2547). MISSION_CURRENT is not a configured
stream in PX4 but the mission manager's once-a-second report on every link; here it is one more 1 Hz stream.
A stream whose builder returns None (no data, e.g. HOME_POSITION before home is set) sends nothing.
"""

from __future__ import annotations

import enum
import logging
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Final

from sitl_emu.mavlink.telemetry import actuators as ta
from sitl_emu.mavlink.telemetry import ground_truth as tg
from sitl_emu.mavlink.telemetry import health as th
from sitl_emu.mavlink.telemetry import messages as tm
from sitl_emu.mavlink.telemetry import sensors as ts
from sitl_emu.mavlink.version import autopilot_version, protocol_version
from sitl_emu.types import VehicleEvent, VehicleSnapshot

if TYPE_CHECKING:
    from sitl_emu.mavlink.context import EndpointContext, OutMessage

log = logging.getLogger(__name__)

HEARTBEAT_ID: Final = 0
HEARTBEAT_INTERVAL_US: Final = 1_000_000
STATUSTEXT_MAX_AGE_US: Final = 5_000_000  # STATUSTEXT.hpp: don't send stale messages
STATUSTEXT_CHUNK: Final = 50


class StreamMode(enum.Enum):
    ONBOARD = "onboard"
    NORMAL = "normal"


# message id -> builder (streamable messages; REQUEST_MESSAGE answers every one of them)
BUILDERS: dict[int, tm.Builder] = {
    0: tm.heartbeat,
    1: th.sys_status,
    2: tm.system_time,
    4: tm.ping,
    8: th.link_node_status,
    24: tm.gps_raw_int,
    29: ts.scaled_pressure,
    30: tm.attitude,
    31: tm.attitude_quaternion,
    32: tm.local_position_ned,
    33: tm.global_position_int,
    36: ta.servo_output_raw,
    42: th.mission_current,
    74: tm.vfr_hud,
    83: tm.attitude_target,
    85: tm.position_target_local_ned,
    105: ts.highres_imu,
    111: tm.timesync,
    132: ts.distance_sensor,
    141: tm.altitude,
    147: tm.battery_status,
    230: th.estimator_status,
    241: ts.vibration,
    242: tm.home_position,
    245: tm.extended_sys_state,
    290: ta.esc_info,
    291: ta.esc_status,
    331: tm.odometry,
    360: tm.orbit_execution_status,  # sends only while orbiting
    380: th.time_estimate_to_target,
    436: tm.current_mode,
    441: ts.gnss_integrity,
    514: th.estimator_sensor_fusion_status,
    12901: ts.open_drone_id_location,
    12904: ts.open_drone_id_system,
}
# streams in PX4's list that no SITL link starts with: on SET_MESSAGE_INTERVAL or REQUEST_MESSAGE only
ON_DEMAND_STREAMS: dict[int, tm.Builder] = {
    115: tg.hil_state_quaternion,  # SIH's ground truth (MAVSDK telemetry.set_rate_ground_truth)
}
STREAMS: dict[int, tm.Builder] = {**BUILDERS, **ON_DEMAND_STREAMS}
# messages PX4 sends only on request (REQUEST_MESSAGE), not as periodic streams
ON_REQUEST: dict[int, tm.Builder] = {
    148: lambda ctx, snap: autopilot_version(ctx.encoder, ctx.sysid),
    300: lambda ctx, snap: protocol_version(),
}

# Hz, from mavlink_main.cpp configure_streams_to_default (MAVLINK_MODE_ONBOARD); GPS_RAW_INT "unlimited" = SIH GPS 8 Hz
ONBOARD_RATES_HZ: dict[int, float] = {
    111: 10, 32: 30, 30: 100, 141: 10, 132: 10, 290: 10, 291: 10, 331: 30, 31: 50, 83: 10, 147: 0.5, 436: 0.5,
    230: 1, 514: 1, 245: 5, 33: 50, 441: 1, 24: 8, 242: 0.5, 12901: 1, 12904: 1, 4: 1, 85: 10, 36: 10, 1: 5, 2: 1,
    380: 1, 74: 10, 241: 0.5, 8: 1, 105: 50, 29: 1, 42: 1, 360: 5,
}
# MAVLINK_MODE_NORMAL with the SITL GCS-link overrides (px4-rc.mavlink: 50 Hz for position/attitude streams)
NORMAL_RATES_HZ: dict[int, float] = {
    141: 1, 30: 50, 31: 50, 83: 50, 147: 0.5, 436: 0.5, 132: 0.5, 290: 1, 291: 1, 230: 0.5, 514: 0.5, 245: 1,
    33: 50, 441: 1, 24: 5, 242: 0.5, 32: 50, 12901: 1, 12904: 1, 4: 0.1, 85: 50, 36: 50, 1: 1, 380: 1, 74: 4,
    241: 0.1, 8: 1, 29: 1, 42: 1, 360: 2,
}
# Builders that read more than the snapshot: the link's own counters (LINK_NODE_STATUS), the vehicle's mission store
# (MISSION_CURRENT) or its physics (HIL_STATE_QUATERNION). Each link builds these itself; SharedBuilds the others.
PER_LINK: frozenset[int] = frozenset({8, 42, 115})
# A stream sends only when its source topic has news: a topic slower than the stream sets the pace. PX4's navigator
# publishes rtl_time_estimate every 2 s, so TIME_ESTIMATE_TO_TARGET (1 Hz configured) goes out at 0.5 Hz.
SOURCE_PERIOD_US: dict[int, int] = {380: 2_000_000}


MAX_INTERVAL_US: Final = 1e12  # set_interval: from here on, PX4's rate is 1e-6 Hz or less, which stops the stream


def _interval_us(hz: float) -> int:
    return round(1e6 / hz)


UNSET: Final = -1  # _Stream.next_us: due at the next pass (a new, re-configured or restarted stream)


@dataclass(slots=True)
class _Stream:
    """One row of a link's stream table (PX4's MavlinkStream): its interval and when it is next due, simulated µs."""

    msg_id: int
    interval_us: int  # never shorter than the period of its source topic (SOURCE_PERIOD_US)
    next_us: int = UNSET


class SharedBuilds:
    """The stream messages built from one snapshot, shared by a vehicle's links.

    When both links send a message in the same tick (ATTITUDE_QUATERNION at 50 Hz on each), it is built once and its
    payload packed once (fastpack.Packed keeps it); each link frames it with its own sequence number and, when
    signing, its own link id. Only for builders that read nothing but the snapshot (not PER_LINK). A builder that
    fails is not remembered: the other link tries again and counts its own error.
    """

    def __init__(self) -> None:
        self._snap: VehicleSnapshot | None = None
        self._built: dict[int, OutMessage | None] = {}
        # whether the links share (the node's step_io says): only while they both send, as a Sim's link builds
        # nothing until a peer talks, and keeping what one link built for none would cost for nothing
        self.active = True

    def build(self, msg_id: int, builder: tm.Builder, ctx: EndpointContext, snap: VehicleSnapshot
              ) -> OutMessage | None:
        if snap is not self._snap:  # a new instant (or an input changed the vehicle): forget the old messages
            self._snap = snap
            self._built = {}
        built = self._built
        if msg_id in built:
            return built[msg_id]
        msg = builder(ctx, snap)
        built[msg_id] = msg
        return msg


class Streams:
    """One link's stream table: interval per message id (None = off) and the next due time, in simulated µs."""

    def __init__(self, mode: StreamMode, start_delay_us: int = 0, shared: SharedBuilds | None = None) -> None:
        """`shared`: the vehicle's SharedBuilds, when its links share what they build in a tick."""
        self.mode = mode
        self.shared = shared
        # the streams (heartbeat included) begin this long after the first pass: runtime/swarm.py staggers its
        # vehicles' links, as separately started PX4 instances are out of phase with each other
        self.start_delay_us = start_delay_us
        self._starting = True  # no pass yet since construction or restart
        rates = ONBOARD_RATES_HZ if mode is StreamMode.ONBOARD else NORMAL_RATES_HZ
        self._default_us: dict[int, int] = {mid: _interval_us(hz) for mid, hz in rates.items()}
        self._interval_us: dict[int, int] = dict(self._default_us)
        # the table PX4 scans each pass, in the order of _interval_us; rebuilt when an interval is set
        self._table: list[_Stream] = []
        self._rebuild_table()
        self._next_heartbeat_us = 0
        self.next_due_us = 0  # nothing is due before this (simulated µs)
        self._statustext_id = 0
        self.build_errors = 0

    def restart(self) -> None:
        for stream in self._table:
            stream.next_us = UNSET
        self._next_heartbeat_us = 0
        self.next_due_us = 0
        self._starting = True

    # --- configuration (SET/GET_MESSAGE_INTERVAL) ------------------------------------------------------------
    def known(self, msg_id: int) -> bool:
        return msg_id in STREAMS

    def set_interval(self, msg_id: int, interval_us: float) -> bool:
        """mavlink_receiver.cpp set_message_interval: <0 stop, 0 default rate, >0 that interval. False: no stream.

        PX4 turns the interval into a rate (1e6 / interval) and configure_stream deletes a stream whose rate is not
        above 1e-6 Hz, so an interval of 1e12 µs or more (infinity too) stops the stream as well."""
        if msg_id == HEARTBEAT_ID or msg_id not in STREAMS:
            return False
        if interval_us < -1e-5 or interval_us >= MAX_INTERVAL_US:
            self._interval_us.pop(msg_id, None)
        elif interval_us <= 1e-5:
            if msg_id in self._default_us:
                self._interval_us[msg_id] = self._default_us[msg_id]
            else:
                self._interval_us.pop(msg_id, None)
        else:
            self._interval_us[msg_id] = max(int(interval_us), 1)
        for stream in self._table:  # the others keep their due times
            if stream.msg_id == msg_id:
                stream.next_us = UNSET
        self._rebuild_table()
        self.next_due_us = 0
        return True

    def get_interval(self, msg_id: int) -> int:
        """Current interval in µs; 0 if the link has no such stream running.

        mavlink_receiver.cpp get_message_interval() starts from `unsigned interval = 0` and only overwrites it for a
        configured stream, so a stopped or unknown stream reads 0 (not the -1 of the MAVLink spec).
        """
        if msg_id == HEARTBEAT_ID:
            return HEARTBEAT_INTERVAL_US
        return self._interval_us.get(msg_id, 0)

    # --- sending -----------------------------------------------------------------------------------------------
    def build(self, msg_id: int, ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage | None:
        """The message now, for REQUEST_MESSAGE; None if we have no such message or no data for it."""
        builder = STREAMS.get(msg_id) or ON_REQUEST.get(msg_id)
        return builder(ctx, snap) if builder is not None else None

    def emit_due(self, ctx: EndpointContext, get_snapshot: Callable[[], VehicleSnapshot]) -> int:
        """Build and send what is due at ctx.now_us (due()); the snapshot is only taken when something is due."""
        now = ctx.now_us
        if now < self.next_due_us:  # the common case, on every link every tick
            return 0
        due = self.due(now)
        if not due:
            return 0
        snap = get_snapshot()
        shared = self.shared
        streams, per_link = STREAMS, PER_LINK  # module globals: one look-up per pass, not one per message
        sent = 0
        for msg_id in due:
            builder = tm.heartbeat if msg_id == HEARTBEAT_ID else streams[msg_id]
            try:
                if shared is None or not shared.active or msg_id in per_link:
                    msg = builder(ctx, snap)
                else:
                    msg = shared.build(msg_id, builder, ctx, snap)
            except Exception as err:  # a bad snapshot value must cost one message, not the link
                self._build_failed(msg_id, err)
                continue
            if msg is not None:
                ctx.send(msg)
                sent += 1
        return sent

    def due(self, now: int) -> list[int]:
        """The message ids due at `now`: HEARTBEAT_ID first if due, then the due streams in table order (a scan of
        the table, as PX4's mavlink main loop does). Each one's next due time is set."""
        if now < self.next_due_us:
            return []
        if self._starting:  # the first pass since construction or restart
            self._starting = False
            if self.start_delay_us > 0:
                self._begin_at(now + self.start_delay_us)
                return []
        due_ids = []
        if now >= self._next_heartbeat_us:
            due_ids.append(HEARTBEAT_ID)
            self._next_heartbeat_us = _next_due(self._next_heartbeat_us, HEARTBEAT_INTERVAL_US, now)
        earliest = self._next_heartbeat_us
        for stream in self._table:
            due_us = now if stream.next_us == UNSET else stream.next_us
            if due_us <= now:
                due_us = stream.next_us = _next_due(due_us, stream.interval_us, now)
                due_ids.append(stream.msg_id)
            if due_us < earliest:
                earliest = due_us
        self.next_due_us = earliest
        return due_ids

    def _begin_at(self, start_us: int) -> None:
        """Nothing goes out before `start_us`; then the heartbeat and every stream are due at once."""
        self._next_heartbeat_us = start_us
        for stream in self._table:
            stream.next_us = start_us
        self.next_due_us = start_us

    def _rebuild_table(self) -> None:
        """The table from the configured intervals, in their order; each stream keeps its due time (UNSET for one
        just configured)."""
        kept = {stream.msg_id: stream.next_us for stream in self._table}
        self._table = [_Stream(mid, max(interval, SOURCE_PERIOD_US.get(mid, 0)), kept.get(mid, UNSET))
                       for mid, interval in self._interval_us.items()]

    def _build_failed(self, msg_id: int, err: Exception) -> None:
        self.build_errors += 1
        if self.build_errors == 1:
            log.error("cannot build message %d: %r", msg_id, err, exc_info=log.isEnabledFor(logging.DEBUG))

    def send_statustexts(self, ctx: EndpointContext, events: Sequence[VehicleEvent]) -> None:
        """STATUSTEXT.hpp: one id per message, chunks of 50 chars with chunk_seq, nothing older than 5 s."""
        for ev in events:
            if not ev.statustext or ctx.now_us - ev.time_us > STATUSTEXT_MAX_AGE_US:
                continue
            for chunk_seq, chunk in enumerate(statustext_chunks(ev.statustext_text)):
                ctx.send(ctx.encoder.statustext_encode(int(ev.severity), chunk, self._statustext_id, chunk_seq))
            self._statustext_id = (self._statustext_id + 1) & 0xFFFF


def statustext_chunks(text: str) -> list[bytes]:
    data = text.encode("utf-8", errors="replace")[:127]  # mavlink_log text is 127 chars + NUL
    chunks = [data[i:i + STATUSTEXT_CHUNK] for i in range(0, len(data), STATUSTEXT_CHUNK)]
    return chunks or [b""]


def _next_due(due: int, interval: int, now: int) -> int:
    nxt = due + interval
    return nxt if nxt > now else now + interval
