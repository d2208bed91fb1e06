"""A pymavlink client's mission transfers against the mission protocol handler in memory (support.handler_ctx):
items as MISSION_ITEM_INT, an upload answering each request, a download item by item (MISSION_REQUEST_INT or the
legacy MISSION_REQUEST)."""

from __future__ import annotations

import math

from sitl_emu.mavlink.protocols.mission import MissionProtocol
from support.handler_ctx import Client, MemoryContext

LAT, LON = 473977420, 85455940
WAYPOINT = 16


def item(client: Client, seq: int, command: int = WAYPOINT, frame: int = 6, mission_type: int = 0,
         x: int = LAT, y: int = LON, params: tuple[float, ...] = (0.0, 0.0, 0.0, math.nan), current: int = 0,
         z: float = 5.0):
    return client.msg("MISSION_ITEM_INT", 1, 1, seq, frame, command, current, 1, *params, x, y, z, mission_type)


def upload(proto: MissionProtocol, ctx: MemoryContext, client: Client, items: list, mission_type: int = 0) -> int:
    """Answer each request with the item asked for; the final MISSION_ACK type."""
    proto.handle(client.msg("MISSION_COUNT", 1, 1, len(items), mission_type), ctx)
    while True:
        (msg,) = ctx.take()
        if msg.get_type() == "MISSION_ACK":
            return msg.type
        assert msg.get_type() == "MISSION_REQUEST_INT" and msg.mission_type == mission_type
        proto.handle(items[msg.seq], ctx)


def download(proto: MissionProtocol, ctx: MemoryContext, client: Client, mission_type: int = 0,
             legacy: bool = False) -> list:
    proto.handle(client.msg("MISSION_REQUEST_LIST", 1, 1, mission_type), ctx)
    (count,) = ctx.take()
    assert count.get_type() == "MISSION_COUNT" and count.mission_type == mission_type
    got = []
    for seq in range(count.count):
        proto.handle(client.msg("MISSION_REQUEST" if legacy else "MISSION_REQUEST_INT", 1, 1, seq, mission_type), ctx)
        got.extend(ctx.take())
    proto.handle(client.msg("MISSION_ACK", 1, 1, 0, mission_type), ctx)
    return got
