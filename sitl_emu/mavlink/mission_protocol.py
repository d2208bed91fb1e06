"""The mission protocol for a vehicle that holds no plan (src/modules/mavlink/mavlink_mission.cpp; reference 9c.4).

sitl_emu does not fly missions yet, so every plan (mission, geofence, rally) is empty:
- MISSION_REQUEST_LIST -> MISSION_COUNT 0 with the requested mission_type echoed, so QGC's connect sequence completes
  (QGC downloads types 0, 1 and 2; the GCS closes the transfer with MISSION_ACK).
- MISSION_COUNT 0 (clear by upload) and MISSION_CLEAR_ALL -> MISSION_ACK ACCEPTED, as PX4.
- MISSION_COUNT > 0 -> refused at once with MISSION_ACK MAV_MISSION_UNSUPPORTED and a report saying so, never left
  hanging (PX4 would request the items; a client then sees its upload fail cleanly instead of a timeout).
- MISSION_ITEM(_INT) outside a transfer -> MISSION_ACK MAV_MISSION_ERROR (PX4: "IGN MISSION_ITEM: No transfer").
- MISSION_REQUEST(_INT) outside a transfer is silently ignored, as PX4 does.
The opaque_id extension field (0 for an empty plan) is not in pymavlink's dialects, so it goes out as 0 anyway.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, ClassVar, cast

from sitl_emu.px4 import Severity

if TYPE_CHECKING:
    from typing import TypeAlias

    from pymavlink.dialects.v20 import development as dialect
    from pymavlink.dialects.v20.development import MAVLink_message

    from sitl_emu.mavlink.context import LinkContext

    _Item: TypeAlias = dialect.MAVLink_mission_item_message | dialect.MAVLink_mission_item_int_message
    # every message of MissionProtocol.MESSAGES: all carry a target and a mission_type
    _MissionMessage: TypeAlias = (
        dialect.MAVLink_mission_request_list_message | dialect.MAVLink_mission_count_message
        | dialect.MAVLink_mission_clear_all_message | _Item | dialect.MAVLink_mission_request_message
        | dialect.MAVLink_mission_request_int_message | dialect.MAVLink_mission_ack_message)

log = logging.getLogger(__name__)

MAV_COMP_ID_MISSIONPLANNER = 190

# MAV_MISSION_RESULT (common.xml)
MAV_MISSION_ACCEPTED = 0
MAV_MISSION_ERROR = 1
MAV_MISSION_UNSUPPORTED = 3

# MAV_MISSION_TYPE (common.xml); PX4 stores these three.
MISSION_TYPE_MISSION = 0
MISSION_TYPE_FENCE = 1
MISSION_TYPE_RALLY = 2
_PLAN_NAMES = {
    MISSION_TYPE_MISSION: ("Mission upload", "missions"),
    MISSION_TYPE_FENCE: ("Geofence upload", "geofences"),
    MISSION_TYPE_RALLY: ("Rally point upload", "rally points"),
}


class MissionProtocol:
    """One instance per link. Stateless: every plan is empty."""

    MESSAGES: ClassVar[tuple[str, ...]] = (
        "MISSION_REQUEST_LIST", "MISSION_COUNT", "MISSION_CLEAR_ALL", "MISSION_ITEM", "MISSION_ITEM_INT",
        "MISSION_REQUEST", "MISSION_REQUEST_INT", "MISSION_ACK",
    )
    TICKS: ClassVar[bool] = False  # tick() never sends: the endpoint need not call it

    def __init__(self) -> None:
        # message type -> its handler, which takes that type's message class (the one place a message is narrowed)
        self._handlers: dict[str, Callable[[Any, LinkContext], None]] = {
            "MISSION_REQUEST_LIST": self._on_request_list,
            "MISSION_COUNT": self._on_count,
            "MISSION_CLEAR_ALL": self._on_clear_all,
            "MISSION_ITEM": self._on_item,
            "MISSION_ITEM_INT": self._on_item,
        }

    def handle(self, msg: MAVLink_message, ctx: LinkContext) -> None:
        if not _addressed_to_us(cast("_MissionMessage", msg), ctx):  # the endpoint sends only MESSAGES
            return
        handler = self._handlers.get(msg.get_type())
        if handler is not None:
            handler(msg, ctx)
        # MISSION_REQUEST(_INT) with no transfer running, and the GCS's closing MISSION_ACK: nothing to do.

    def tick(self, ctx: LinkContext) -> None:
        """Nothing to stream: an empty plan is answered in one message."""

    @staticmethod
    def _on_request_list(msg: dialect.MAVLink_mission_request_list_message, ctx: LinkContext) -> None:
        if msg.mission_type not in _PLAN_NAMES:
            _ack(msg, ctx, MAV_MISSION_UNSUPPORTED)
            return
        ctx.send(ctx.mav.mission_count_encode(msg.get_srcSystem(), msg.get_srcComponent(), 0, msg.mission_type))

    @staticmethod
    def _on_count(msg: dialect.MAVLink_mission_count_message, ctx: LinkContext) -> None:
        if msg.count == 0:  # uploading an empty plan clears it: accepted
            _ack(msg, ctx, MAV_MISSION_ACCEPTED)
            return
        what, plural = _PLAN_NAMES.get(msg.mission_type, ("Upload", "this plan type"))
        ctx.vehicle.report(Severity.CRITICAL, "mavlink", f"{what} refused: {plural} are not supported yet",
                           is_event=False)
        _ack(msg, ctx, MAV_MISSION_UNSUPPORTED)

    @staticmethod
    def _on_clear_all(msg: dialect.MAVLink_mission_clear_all_message, ctx: LinkContext) -> None:
        _ack(msg, ctx, MAV_MISSION_ACCEPTED)

    @staticmethod
    def _on_item(msg: _Item, ctx: LinkContext) -> None:
        ctx.vehicle.report(Severity.CRITICAL, "mavlink", "IGN MISSION_ITEM: No transfer")
        _ack(msg, ctx, MAV_MISSION_ERROR)


def _addressed_to_us(msg: _MissionMessage, ctx: LinkContext) -> bool:
    """CHECK_SYSID_COMPID_MISSION: own sysid exactly; own compid, the mission planner's (190) or 0."""
    return msg.target_system == ctx.sysid and msg.target_component in (ctx.compid, MAV_COMP_ID_MISSIONPLANNER, 0)


def _ack(msg: _MissionMessage, ctx: LinkContext, result: int) -> None:
    mission_type = getattr(msg, "mission_type", MISSION_TYPE_MISSION)
    ctx.send(ctx.mav.mission_ack_encode(msg.get_srcSystem(), msg.get_srcComponent(), result, mission_type))
