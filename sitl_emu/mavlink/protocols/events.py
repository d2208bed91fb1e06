"""PX4's events interface on one link (src/modules/mavlink/mavlink_events.cpp/.h, as libevents' receive.h expects it).

- Events (the vehicle's px4_events_after: the PX4 event beside each '\\t'-terminated text, sitl_emu/events/
  catalogue.py, and those the commander sends alone: failsafe notices, the health and arming check report) get PX4's
  global sequence, which starts at events::initial_event_sequence (65535 - 10, so it wraps soon) and counts one per
  event, and go into a ring buffer of the last 20 (EventBuffer's default capacity).
- Each new event goes out at once as EVENT (destination 0/0 = everyone, event_time_boot_ms, id, sequence,
  log_levels, the 40 argument bytes). Before the first one, CURRENT_EVENT_SEQUENCE with the RESET flag tells a
  client where the sequence starts.
- CURRENT_EVENT_SEQUENCE (the newest sequence; flags RESET while the buffer is empty) every 3 s
  (current_sequence_interval), so a client notices what it missed and asks for it. (SendProtocol also has an
  on_gcs_connected() that sends it at once; nothing in PX4's mavlink module calls it, and PX4 SIH's GCS link shows
  the plain 3 s rhythm, ../shared/reference/px4-gcs-streams.json.)
- REQUEST_EVENT (first..last sequence) is answered from the buffer, whatever its target (mavlink_receiver.cpp hands
  every one to handle_request_event): EVENT for each sequence it
  still holds, RESPONSE_EVENT_ERROR (reason UNAVAILABLE, with the oldest sequence after it still available) for each
  it does not; a range longer than the buffer gets one error for its start and only its newest 20 are looked up.
A reboot of the vehicle starts the sequence and the buffer again. Each link keeps its own copy of the buffer; both
see the same vehicle events in the same order, so their sequences agree as PX4's shared buffer makes them.
"""

from __future__ import annotations

from collections import deque
from typing import TYPE_CHECKING, ClassVar, Final

from sitl_emu.events.catalogue import Px4Event
from sitl_emu.mavlink.wire.extra_messages import EXTRA, decode, payload_of_unknown, source_of_unknown

if TYPE_CHECKING:
    from pymavlink.dialects.v20.development import MAVLink_message

    from sitl_emu.mavlink.context import LinkContext

INITIAL_EVENT_SEQUENCE: Final = 65535 - 10
BUFFER_CAPACITY: Final = 20
CURRENT_SEQUENCE_INTERVAL_US: Final = 3_000_000  # Final: compiled, read as a constant at every tick
MAV_EVENT_CURRENT_SEQUENCE_FLAGS_RESET: Final = 1
MAV_EVENT_ERROR_REASON_UNAVAILABLE: Final = 0
MAV_COMP_ID_ALL: Final = 0
REQUEST_EVENT_ID: Final = 412


class EventBuffer:
    """The newest `capacity` events by sequence, and the newest sequence given out."""

    def __init__(self, capacity: int = BUFFER_CAPACITY) -> None:
        self.capacity = capacity
        self.events: deque[tuple[int, Px4Event]] = deque(maxlen=capacity)
        self.latest_sequence = INITIAL_EVENT_SEQUENCE

    def insert(self, event: Px4Event) -> int:
        self.latest_sequence = (self.latest_sequence + 1) & 0xFFFF
        self.events.append((self.latest_sequence, event))
        return self.latest_sequence

    def get(self, sequence: int) -> Px4Event | None:
        return next((e for s, e in self.events if s == sequence), None)

    def oldest_sequence_after(self, sequence: int) -> int:
        """The held sequence closest after `sequence` (wrapping), or the newest if none is."""
        after = [s for s, _ in self.events if s != sequence]
        return min(after, key=lambda s: (s - sequence) & 0xFFFF, default=self.latest_sequence)


class EventsProtocol:
    """mavlink_events' SendProtocol for one link, fed from the vehicle's events."""

    MESSAGES: ClassVar[tuple[str, ...]] = (f"UNKNOWN_{REQUEST_EVENT_ID}",)  # pymavlink 2.4 lacks REQUEST_EVENT

    def __init__(self) -> None:
        self.buffer = EventBuffer()
        self._vehicle_seq = -1
        self._sent_any = False
        self._last_current_sequence_us = 0
        self._last_now_us = 0

    def handle(self, msg: MAVLink_message, ctx: LinkContext) -> None:
        frame = bytes(getattr(msg, "data", b""))
        if len(frame) < 2:
            return
        request = decode(REQUEST_EVENT_ID, payload_of_unknown(frame))
        # pymavlink does not know this message's target fields; with them the link forwards it as PX4's
        # forward_message does (a request for this vehicle stays here, a broadcast one goes on)
        for field in ("target_system", "target_component"):
            setattr(msg, field, request[field])
        self._answer(request["first_sequence"], request["last_sequence"], source_of_unknown(frame), ctx)

    def _answer(self, first: int, last: int, requester: tuple[int, int], ctx: LinkContext) -> None:
        end = (last + 1) & 0xFFFF
        sequence = first
        if (end - sequence) & 0xFFFF > self.buffer.capacity:
            self._send_unavailable(sequence, requester, ctx)
            sequence = (end - self.buffer.capacity) & 0xFFFF
        while sequence != end:
            event = self.buffer.get(sequence)
            if event is not None:
                self._send_event(sequence, event, ctx)
            else:
                self._send_unavailable(sequence, requester, ctx)
            sequence = (sequence + 1) & 0xFFFF

    def _send_unavailable(self, sequence: int, requester: tuple[int, int], ctx: LinkContext) -> None:
        ctx.send(EXTRA.response_event_error_encode(requester[0], requester[1], sequence,
                                                   self.buffer.oldest_sequence_after(sequence),
                                                   MAV_EVENT_ERROR_REASON_UNAVAILABLE))

    def tick(self, ctx: LinkContext) -> bool:
        now_us = ctx.now_us
        if now_us < self._last_now_us:  # the vehicle rebooted: PX4 starts its sequence again
            self.buffer = EventBuffer()
            self._sent_any = False
            self._last_current_sequence_us = 0
        self._last_now_us = now_us
        for seq, event in ctx.vehicle.px4_events_after(self._vehicle_seq):
            self._vehicle_seq = seq
            self._publish(event, ctx)
        if now_us - self._last_current_sequence_us > CURRENT_SEQUENCE_INTERVAL_US:
            self._send_current_sequence(ctx)
        return True

    def _publish(self, event: Px4Event, ctx: LinkContext) -> None:
        sequence = self.buffer.insert(event)
        if not self._sent_any:  # SendProtocol::update's first event: the sequence starts here
            self._sent_any = True
            self._send_current_sequence(ctx, reset=True)
        self._send_event(sequence, event, ctx)

    def _send_event(self, sequence: int, event: Px4Event, ctx: LinkContext) -> None:
        ctx.send(EXTRA.event_encode(MAV_COMP_ID_ALL, 0, event.id, event.time_ms & 0xFFFFFFFF, sequence,
                                    event.log_levels, tuple(event.arguments)))

    def _send_current_sequence(self, ctx: LinkContext, reset: bool = False) -> None:
        self._last_current_sequence_us = ctx.now_us
        flags = MAV_EVENT_CURRENT_SEQUENCE_FLAGS_RESET if reset or not self.buffer.events else 0
        ctx.send(EXTRA.current_event_sequence_encode(self.buffer.latest_sequence, flags))
