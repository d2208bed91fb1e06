"""The mission protocol for mission, geofence and rally plans, as src/modules/mavlink/mavlink_mission.cpp runs it.

One MissionProtocol per link, a state machine IDLE / GETLIST (receiving an upload) / SENDLIST (sending a download):
- Upload: MISSION_COUNT n -> MISSION_REQUEST_INT 0 (MISSION_REQUEST when the client speaks the legacy float
  messages) -> MISSION_ITEM_INT 0 -> ... -> MISSION_ACK ACCEPTED. An item out of sequence is dropped; the
  request is repeated every 250 ms (MAVLINK_MISSION_RETRY_TIMEOUT_DEFAULT) until 5 s pass without a message from
  the client (MAVLINK_MISSION_PROTOCOL_TIMEOUT_DEFAULT): then "Mission sync timeout" (PX4 main's wording, the
  reference's `bad.out_of_sequence`) and the partial upload is dropped, the stored plan untouched. A refused item
  (mission_items.parse_item) ends the transfer with its MAV_MISSION_RESULT and "IGN MISSION_ITEM: Invalid item".
  The plan is stored only when the last item arrives (mission_store.py: never half-written). MISSION_COUNT 0
  clears the plan; more than the plan holds -> MAV_MISSION_NO_SPACE.
- Download: MISSION_REQUEST_LIST -> MISSION_COUNT (repeated every 250 ms until the first request, as PX4 main does
  since PR 26872) -> MISSION_REQUEST_INT i -> MISSION_ITEM_INT i (`current` set on the mission's current item) ->
  the client's MISSION_ACK. A download never acknowledged also ends with "Mission sync timeout" after 5 s.
- MISSION_CLEAR_ALL (one plan type or MAV_MISSION_TYPE_ALL), MISSION_SET_CURRENT (index inside the mission).
- One upload at a time on the whole vehicle (PX4's static _transfer_in_progress): a MISSION_COUNT on another link
  meanwhile gets MAV_MISSION_ERROR. A client other than the transfer partner gets PX4's "partner id mismatch".
MISSION_REQUEST_PARTIAL_LIST / MISSION_WRITE_PARTIAL_LIST are not handled by PX4 (handle_message has no case for
them), so they are ignored here too; an abandoned or broken transfer is the "partial" case PX4 knows (the timeout).
Not on the wire: the opaque_id of MISSION_COUNT / MISSION_ACK and MISSION_CURRENT's plan ids, because pymavlink's
dialects (2.4.x, development included) lack those extension fields; the store keeps a CRC32 per plan for them.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from enum import Enum
from typing import TYPE_CHECKING, Any, ClassVar

from sitl_emu.mavlink.protocols.mission_items import (
    MAV_MISSION_ACCEPTED,
    MAV_MISSION_ERROR,
    MAV_MISSION_INVALID,
    MAV_MISSION_NO_SPACE,
    MAV_MISSION_OPERATION_CANCELLED,
    MAV_MISSION_UNSUPPORTED,
    item_message,
    mission_current_fields,
    parse_item,
    plan_check,
)
from sitl_emu.navigator.mission_store import (
    MAX_ITEMS,
    PLAN_ALL,
    PLAN_MISSION,
    PLAN_TYPES,
    MissionItem,
    MissionStore,
    plan_id,
)
from sitl_emu.px4 import Severity

if TYPE_CHECKING:
    from pymavlink.dialects.v20.development import MAVLink_message

    from sitl_emu.mavlink.context import LinkContext

log = logging.getLogger(__name__)

MAV_COMP_ID_MISSIONPLANNER = 190
RETRY_US = 250_000  # MAVLINK_MISSION_RETRY_TIMEOUT_DEFAULT
TIMEOUT_US = 5_000_000  # MAVLINK_MISSION_PROTOCOL_TIMEOUT_DEFAULT
REPEAT_US = 1_000_000  # the slow rate limiter of MavlinkMissionManager::send


class TransferState(Enum):
    """MavlinkMissionManager's _state: no transfer, receiving an upload, sending a download."""

    IDLE = "idle"
    GETLIST = "getlist"
    SENDLIST = "sendlist"


class MissionProtocol:
    """One instance per link; the plans and the upload lock live in the vehicle's MissionStore."""

    # MESSAGES: the keys of _HANDLERS, at the end of the class (the handlers must be defined first)
    WATCHES_VEHICLE: ClassVar[bool] = True  # tick() reports the mission progress (context.vehicle_news)

    def __init__(self) -> None:
        self._state = TransferState.IDLE
        self._type = PLAN_MISSION
        self._partner = (0, 0)  # PX4 starts with partner 0/0: a stray item before any transfer is a "mismatch"
        self._seq = 0  # the next item to receive, or the next request expected
        self._count = 0
        self._int_mode = True
        self._items: list[MissionItem] = []
        self._marked_current = -1
        self._sent_us = 0
        self._recv_us = 0
        self._seen: tuple[int, bool] | None = None  # (current item, finished) last reported
        self._seen_reached = -1
        self._reached_repeats = 0  # PX4 sends the last MISSION_ITEM_REACHED again with each 1 Hz report, 10 times
        self._next_repeat_us = 0

    def handle(self, msg: MAVLink_message, ctx: LinkContext) -> None:
        if not _addressed_to_us(msg, ctx):
            return
        kind = msg.get_type()
        if kind in ("MISSION_ITEM", "MISSION_ITEM_INT", "MISSION_REQUEST", "MISSION_REQUEST_INT"):
            self._int_mode = kind.endswith("_INT")  # PX4 follows the client's choice of message
        self._HANDLERS[kind](self, msg, ctx)

    def tick(self, ctx: LinkContext) -> bool:
        """Mission progress, retries and the protocol timeout (MavlinkMissionManager::send); False when no transfer
        is under way and no MISSION_ITEM_REACHED repeat is due (idle until news or a message)."""
        self._report_progress(ctx)
        if self._state is TransferState.IDLE:
            return self._reached_repeats > 0
        now = ctx.now_us
        if now - self._sent_us > RETRY_US and self._state is TransferState.GETLIST:
            self._request(ctx, self._seq)
        elif now - self._sent_us > RETRY_US and self._state is TransferState.SENDLIST and self._seq == 0:
            self._send_count(ctx, self._count)
        elif now - self._recv_us > TIMEOUT_US:
            _say(ctx, "Mission sync timeout")
            self._end(ctx)
        return True

    def _report_progress(self, ctx: LinkContext) -> None:
        """The navigator's mission_result as send() reports it: MISSION_CURRENT at once when the current item or the
        finished flag changes, MISSION_ITEM_REACHED when another item is reached (only the latest is seen when two
        are reached between two reads). The once-a-second MISSION_CURRENT is a telemetry stream here."""
        store = _store(ctx)
        seen = (store.current_seq, store.finished)
        if self._seen is None:
            self._seen = seen
        elif seen != self._seen:
            self._seen = seen
            if store.count(PLAN_MISSION) > 0:
                fields = mission_current_fields(store, ctx.vehicle.snapshot().nav_state)
                ctx.send(ctx.encoder.mission_current_encode(*fields))
        if store.seq_reached != self._seen_reached:
            self._seen_reached = store.seq_reached
            self._reached_repeats = 0
            if store.count(PLAN_MISSION) > 0 and store.seq_reached >= 0:
                ctx.send(ctx.encoder.mission_item_reached_encode(store.seq_reached))
                self._reached_repeats, self._next_repeat_us = 10, ctx.now_us + REPEAT_US
        elif self._reached_repeats and ctx.now_us >= self._next_repeat_us and store.count(PLAN_MISSION) > 0:
            ctx.send(ctx.encoder.mission_item_reached_encode(self._seen_reached))
            self._reached_repeats -= 1
            self._next_repeat_us = ctx.now_us + REPEAT_US

    # ---- upload ---------------------------------------------------------------------------------------------------
    def _on_count(self, msg: Any, ctx: LinkContext) -> None:
        sender = _sender(msg)
        if self._state is TransferState.GETLIST:
            self._count_while_receiving(msg, ctx, sender)
            return
        if self._state is TransferState.SENDLIST:
            _say(ctx, "WPM: IGN MISSION_COUNT: Busy")
            self._ack(ctx, MAV_MISSION_ERROR, sender, msg.mission_type)
            return
        store = _store(ctx)
        if not store.try_lock(self):  # another link is uploading
            self._ack(ctx, MAV_MISSION_ERROR, sender, msg.mission_type)
            return
        self._recv_us, self._partner, self._type = ctx.now_us, sender, msg.mission_type
        result = self._start_upload(msg.count, store)
        if result is not None:
            store.unlock(self)
            self._ack(ctx, result)
            return
        self._request(ctx, 0)

    def _start_upload(self, count: int, store: MissionStore) -> int | None:
        """GETLIST for `count` items; or the answer at once (too many, an empty plan stored, an unknown type)."""
        if count > MAX_ITEMS.get(self._type, 0):
            return MAV_MISSION_NO_SPACE
        if self._type not in PLAN_TYPES:
            return MAV_MISSION_INVALID
        if count == 0:
            store.clear(self._type)
            return MAV_MISSION_ACCEPTED
        self._state, self._seq, self._count = TransferState.GETLIST, 0, count
        self._items, self._marked_current = [], -1
        return None

    def _count_while_receiving(self, msg: Any, ctx: LinkContext, sender: tuple[int, int]) -> None:
        self._recv_us = ctx.now_us
        if sender != self._partner:
            self._ack(ctx, MAV_MISSION_ERROR, sender, msg.mission_type)
        elif self._seq == 0:  # our first request was lost: ask again
            self._request(ctx, 0)
        else:
            _say(ctx, "WPM: REJ. CMD: Busy")
            self._ack(ctx, MAV_MISSION_ERROR)

    def _on_item(self, msg: Any, ctx: LinkContext) -> None:
        if _sender(msg) != self._partner:
            _say(ctx, "REJ. MIS ITEM: partner id mismatch")
        elif msg.mission_type != self._type:
            self._ack(ctx, MAV_MISSION_ERROR)
        elif self._state is TransferState.IDLE:
            self._item_while_idle(msg, ctx)
        elif self._state is TransferState.SENDLIST:
            _say(ctx, "IGN MISSION_ITEM: Busy")
            self._ack(ctx, MAV_MISSION_ERROR)
        else:
            self._recv_us = ctx.now_us
            if msg.seq == self._seq:  # an item out of sequence is dropped: the retry asks for the right one
                self._take_item(msg, ctx)

    def _item_while_idle(self, msg: Any, ctx: LinkContext) -> None:
        if self._seq == msg.seq + 1 and self._count == self._seq:
            self._ack(ctx, MAV_MISSION_ACCEPTED)  # the last item again: the client missed our final ACK
        else:
            _say(ctx, "IGN MISSION_ITEM: No transfer")
            self._ack(ctx, MAV_MISSION_ERROR)

    def _take_item(self, msg: Any, ctx: LinkContext) -> None:
        result, item = parse_item(msg, self._int_mode)
        if item is None:
            _say(ctx, "IGN MISSION_ITEM: Invalid item")
            self._ack(ctx, result)
            self._end(ctx)
            return
        if not plan_check(self._type, item):
            self._ack(ctx, MAV_MISSION_ERROR)
            self._end(ctx)
            return
        self._items.append(item)
        if msg.current:
            self._marked_current = msg.seq
        self._seq = msg.seq + 1
        if self._seq < self._count:
            self._request(ctx, self._seq)
            return
        self._store_upload(ctx)
        self._state = TransferState.IDLE
        self._ack(ctx, MAV_MISSION_ACCEPTED)
        _store(ctx).unlock(self)

    def _store_upload(self, ctx: LinkContext) -> None:
        store = _store(ctx)
        items = tuple(self._items)
        if self._type == PLAN_MISSION:
            # PX4's navigator looks these up (its feasibility checks) once a mission exists: listed from now on
            ctx.vehicle.params.mark_used("MIS_DIST_1WP")
            ctx.vehicle.params.mark_used("MIS_TKO_LAND_REQ")
        if plan_id(items) != store.plan(self._type).opaque_id or store.count(self._type) == 0:
            store.replace(self._type, items, self._marked_current)  # PX4 updates only a changed plan

    def _request(self, ctx: LinkContext, seq: int) -> None:
        self._sent_us = ctx.now_us
        if self._int_mode:
            ctx.send(ctx.encoder.mission_request_int_encode(*self._partner, seq, self._type))
        else:
            ctx.send(ctx.encoder.mission_request_encode(*self._partner, seq, self._type))

    # ---- download -------------------------------------------------------------------------------------------------
    def _on_request_list(self, msg: Any, ctx: LinkContext) -> None:
        sender = _sender(msg)
        if self._state is TransferState.SENDLIST and self._seq == self._count:
            # everything was sent: a new request may start even without the client's ACK
            self._state = TransferState.IDLE
        same = self._state is TransferState.SENDLIST and self._type == msg.mission_type and sender == self._partner
        if self._state is not TransferState.IDLE and not same:
            _say(ctx, "Mission download request ignored, already active", Severity.INFO)
            return
        self._state, self._type, self._partner = TransferState.SENDLIST, msg.mission_type, sender
        self._recv_us, self._seq = ctx.now_us, 0
        self._count = _store(ctx).count(self._type) if self._type in PLAN_TYPES else 0
        self._send_count(ctx, self._count)

    def _send_count(self, ctx: LinkContext, count: int) -> None:
        self._sent_us = ctx.now_us
        ctx.send(ctx.encoder.mission_count_encode(*self._partner, count, self._type))

    def _on_request(self, msg: Any, ctx: LinkContext) -> None:
        if _sender(msg) != self._partner:
            _say(ctx, "WPM: REJ. CMD: partner id mismatch")
        elif self._state is TransferState.GETLIST:
            _say(ctx, "WPM: REJ. CMD: Busy")
        elif self._state is TransferState.SENDLIST and msg.mission_type == self._type:
            self._recv_us = ctx.now_us
            if msg.seq == self._seq and self._seq < self._count:
                self._seq += 1
            elif msg.seq != self._seq - 1:  # neither the next item nor the last one again
                self._refuse_request(ctx)
                return
            self._send_item(ctx, msg.seq)
        # TransferState.IDLE: silently ignored, as PX4 does ("some OSDs have buggy mission protocol implementations")

    def _send_item(self, ctx: LinkContext, seq: int) -> None:
        store = _store(ctx)
        plan = store.plan(self._type)
        if seq >= plan.count:  # the plan changed under the download
            self._refuse_request(ctx)
            return
        current = seq == store.current_seq  # PX4 compares with the mission's current item for every plan type
        self._sent_us = ctx.now_us
        ctx.send(item_message(ctx.encoder, self._partner, plan.items[seq], current, self._type, self._int_mode))

    def _refuse_request(self, ctx: LinkContext) -> None:
        self._state = TransferState.IDLE
        self._ack(ctx, MAV_MISSION_ERROR)
        _say(ctx, "WPM: REJ. CMD: Req. WP was unexpected")

    def _on_ack(self, msg: Any, ctx: LinkContext) -> None:
        if _sender(msg) != self._partner:
            _say(ctx, "REJ. WP CMD: partner id mismatch")
        elif self._state is TransferState.SENDLIST and msg.mission_type == self._type:
            self._state = TransferState.IDLE  # the download is over, whatever the client says
        elif self._state is TransferState.GETLIST and msg.type == MAV_MISSION_UNSUPPORTED:
            self._int_mode = not self._int_mode  # the client cannot send this flavour: ask for the other
            self._request(ctx, self._seq)
        elif self._state is TransferState.GETLIST and msg.type == MAV_MISSION_OPERATION_CANCELLED:
            self._end(ctx)

    # ---- clear, set current -----------------------------------------------------------------------------------------
    def _on_clear_all(self, msg: Any, ctx: LinkContext) -> None:
        if self._state is not TransferState.IDLE:
            _say(ctx, "WPM: IGN CLEAR CMD: Busy")
            return
        if msg.mission_type in PLAN_TYPES or msg.mission_type == PLAN_ALL:
            _store(ctx).clear(msg.mission_type)
        self._ack(ctx, MAV_MISSION_ACCEPTED, _sender(msg), msg.mission_type)

    def _on_set_current(self, msg: Any, ctx: LinkContext) -> None:
        if self._state is not TransferState.IDLE:
            _say(ctx, "WPM: IGN WP CURR CMD: Busy")
            return
        store = _store(ctx)
        if not store.set_current(msg.seq):
            _say(ctx, "WPM: WP CURR CMD: Not in list")
            return
        # the navigator's mission_result changes: every link reports the new current item at its next pass
        # (_report_progress)

    # ---- helpers ----------------------------------------------------------------------------------------------------
    def _end(self, ctx: LinkContext) -> None:
        self._state = TransferState.IDLE
        _store(ctx).unlock(self)

    def _ack(self, ctx: LinkContext, result: int, target: tuple[int, int] | None = None,
             mission_type: int | None = None) -> None:
        to = self._partner if target is None else target
        kind = self._type if mission_type is None else mission_type
        ctx.send(ctx.encoder.mission_ack_encode(*to, result, kind))

    # ---- dispatch ---------------------------------------------------------------------------------------------------
    _HANDLERS: ClassVar[dict[str, Callable[[MissionProtocol, Any, LinkContext], None]]] = {
        "MISSION_REQUEST_LIST": _on_request_list, "MISSION_COUNT": _on_count, "MISSION_CLEAR_ALL": _on_clear_all,
        "MISSION_ITEM": _on_item, "MISSION_ITEM_INT": _on_item, "MISSION_REQUEST": _on_request,
        "MISSION_REQUEST_INT": _on_request, "MISSION_ACK": _on_ack, "MISSION_SET_CURRENT": _on_set_current,
    }
    MESSAGES: ClassVar[tuple[str, ...]] = tuple(_HANDLERS)  # the endpoint routes these here


def _store(ctx: LinkContext) -> MissionStore:
    return ctx.vehicle.mission_store()


def _sender(msg: Any) -> tuple[int, int]:
    return msg.get_srcSystem(), msg.get_srcComponent()


def _say(ctx: LinkContext, text: str, severity: Severity = Severity.CRITICAL) -> None:
    """PX4's send_statustext_critical/_info: a tab-terminated STATUSTEXT (it is also an event) on every link."""
    ctx.vehicle.report(severity, "mavlink", text)


def _addressed_to_us(msg: Any, ctx: LinkContext) -> bool:
    """CHECK_SYSID_COMPID_MISSION: own sysid exactly; own compid, the mission planner's (190) or 0."""
    return msg.target_system == ctx.sysid and msg.target_component in (ctx.compid, MAV_COMP_ID_MISSIONPLANNER, 0)
