"""Commands the mavlink module answers itself; everything else goes to the vehicle (commander, navigator...).

Sources: src/modules/mavlink/mavlink_receiver.cpp handle_message_command_both (~l.800-930), set_message_interval,
get_message_interval; reference 3.9-3.12. PX4 <= v1.17 still answers the legacy REQUEST_AUTOPILOT_CAPABILITIES (520),
REQUEST_PROTOCOL_VERSION (519) and GET_HOME_POSITION (410) as aliases of REQUEST_MESSAGE; main removed them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

from sitl_emu.mavlink.protocols.component_metadata import MSG_COMPONENT_METADATA, component_metadata_message
from sitl_emu.mavlink.telemetry.modes import available_modes
from sitl_emu.px4 import MavCmd, MavResult
from sitl_emu.types import VehicleCommand

if TYPE_CHECKING:
    from sitl_emu.mavlink.context import EndpointContext, OutMessage
    from sitl_emu.mavlink.telemetry.streams import Streams

MSG_HOME_POSITION = 242
MSG_MESSAGE_INTERVAL = 244
MSG_AUTOPILOT_VERSION = 148
MSG_PROTOCOL_VERSION = 300
MSG_AVAILABLE_MODES = 435

# legacy request commands -> the message they ask for (PX4@2024 mavlink_receiver.cpp)
LEGACY_REQUESTS: dict[int, int] = {
    MavCmd.REQUEST_AUTOPILOT_CAPABILITIES: MSG_AUTOPILOT_VERSION,
    MavCmd.REQUEST_PROTOCOL_VERSION: MSG_PROTOCOL_VERSION,
    MavCmd.GET_HOME_POSITION: MSG_HOME_POSITION,
}
# commands accepted whatever their target_component (PX4@2024 evaluate_target_ok)
ANY_COMPONENT = frozenset({MavCmd.REQUEST_AUTOPILOT_CAPABILITIES, MavCmd.REQUEST_PROTOCOL_VERSION})
MAVLINK_MODULE_COMMANDS = frozenset({MavCmd.GET_MESSAGE_INTERVAL, MavCmd.SET_MESSAGE_INTERVAL,
                                     MavCmd.REQUEST_MESSAGE, *LEGACY_REQUESTS})


class CommandHandler:
    """Runs one command on behalf of a link; returns the MAV_RESULT to ACK, or None when the vehicle answers.

    `streams` is the link's stream table, which the message-interval and request commands read and configure.
    """

    def __init__(self, streams: Streams) -> None:
        self._streams = streams

    def execute(self, cmd: VehicleCommand, ctx: EndpointContext) -> int | None:
        """Mavlink-module commands are answered here (ACK on this link); the rest go to the vehicle."""
        if cmd.command in MAVLINK_MODULE_COMMANDS:
            result = self._mavlink_command(cmd, ctx)
            ctx.send(ctx.encoder.command_ack_encode(cmd.command, result, 0, 0, cmd.source_system, cmd.source_component))
            return result
        ack = ctx.vehicle.handle_command(cmd)
        ctx.node.invalidate_snapshot()
        if ack is None:
            return None
        ctx.node.route_ack(ack.command, int(ack.result), cmd.source_system, cmd.source_component)
        return int(ack.result)

    def _mavlink_command(self, cmd: VehicleCommand, ctx: EndpointContext) -> int:
        if cmd.command == MavCmd.SET_MESSAGE_INTERVAL:
            return self._set_interval(cmd)
        if cmd.command == MavCmd.GET_MESSAGE_INTERVAL:
            return self._get_interval(_msg_id(cmd.param(1)), ctx)
        if cmd.command == MavCmd.REQUEST_MESSAGE:
            msg_id = _msg_id(cmd.param(1))
            if msg_id == MSG_MESSAGE_INTERVAL:
                return self._get_interval(_msg_id(cmd.param(2)), ctx)
            if msg_id == MSG_AVAILABLE_MODES:
                return self._send_all(available_modes(ctx, cmd.param(2)), ctx)
            if msg_id == MSG_COMPONENT_METADATA:
                return self._send_all([component_metadata_message(ctx.now_us // 1000)], ctx)
            return self._request(msg_id, ctx)
        return self._request(LEGACY_REQUESTS[cmd.command], ctx)

    def _set_interval(self, cmd: VehicleCommand) -> int:
        # set_message_interval(): param3, param4 and param7 (response target) must be 0 or NaN
        for i in (3, 4, 7):
            p = cmd.param(i)
            if math.isfinite(p) and int(p + 0.5) != 0:
                return MavResult.FAILED
        msg_id = _msg_id(cmd.param(1))
        interval_us = cmd.param(2)
        if msg_id is None or math.isnan(interval_us):
            return MavResult.FAILED
        return MavResult.ACCEPTED if self._streams.set_interval(msg_id, interval_us) else MavResult.FAILED

    def _get_interval(self, msg_id: int | None, ctx: EndpointContext) -> int:
        if msg_id is None:
            return MavResult.FAILED
        ctx.send(ctx.encoder.message_interval_encode(msg_id, self._streams.get_interval(msg_id)))
        return MavResult.ACCEPTED

    def _request(self, msg_id: int | None, ctx: EndpointContext) -> int:
        """REQUEST_MESSAGE: the message goes out on this link before the ACK; DENIED if no stream or no data."""
        if msg_id is None:
            return MavResult.DENIED
        msg = self._streams.build(msg_id, ctx, ctx.node.snapshot())
        return self._send_all(None if msg is None else [msg], ctx)

    @staticmethod
    def _send_all(msgs: Sequence[OutMessage] | None, ctx: EndpointContext) -> int:
        if not msgs:
            return MavResult.DENIED
        for msg in msgs:
            ctx.send(msg)
        return MavResult.ACCEPTED


def _msg_id(value: float) -> int | None:
    if not math.isfinite(value) or not 0 <= value <= 0xFFFFFF:
        return None
    return int(value)
