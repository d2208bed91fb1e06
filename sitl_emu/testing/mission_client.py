"""Mission helpers for the scripted client (testing/client.py): build a plan, upload it, start it, wait for items.

    items = [takeoff(home, 5.0), waypoint(home, 12, 0, 5.0), waypoint(home, -6, 12, 5.0), return_to_launch()]
    upload_mission(client, items)
    start_mission(client)                       # MISSION_START: AUTO.MISSION and arm
    wait_reached(client, len(items) - 1, 60.0)  # MISSION_ITEM_REACHED of the last item

The upload is the MAVLink mission protocol as a ground station runs it (MISSION_COUNT, then a MISSION_ITEM_INT for
each MISSION_REQUEST_INT, until MISSION_ACK), so it works against sitl-emu and real PX4 SITL alike.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from sitl_emu.geo import GeoRef, ned_to_global
from sitl_emu.px4 import MavCmd, MavResult
from sitl_emu.testing.client import FlightClient, FlightError

NAN = math.nan
FRAME_MISSION, FRAME_GLOBAL_RELATIVE_ALT_INT = 2, 6
MAV_MISSION_ACCEPTED = 0


@dataclass(frozen=True, slots=True)
class PlanItem:
    """One mission item: a MAV_CMD, its four params, a position (degrees, metres above home) where it has one."""

    command: int
    lat_deg: float = 0.0
    lon_deg: float = 0.0
    alt_m: float = 0.0
    params: tuple[float, float, float, float] = (0.0, 0.0, 0.0, NAN)
    frame: int = FRAME_GLOBAL_RELATIVE_ALT_INT


def _offset(home: tuple[float, float], north_m: float, east_m: float) -> tuple[float, float]:
    lat, lon, _ = ned_to_global(GeoRef(home[0], home[1], 0.0), (north_m, east_m, 0.0))
    return lat, lon


def takeoff(home: tuple[float, float], alt_m: float) -> PlanItem:
    return PlanItem(MavCmd.NAV_TAKEOFF, home[0], home[1], alt_m)


def waypoint(home: tuple[float, float], north_m: float, east_m: float, alt_m: float, hold_s: float = 0.0,
             acceptance_m: float = 0.0) -> PlanItem:
    """A waypoint `north_m`/`east_m` from `home` (lat, lon), `alt_m` above home."""
    lat, lon = _offset(home, north_m, east_m)
    return PlanItem(16, lat, lon, alt_m, (hold_s, acceptance_m, 0.0, NAN))


def return_to_launch() -> PlanItem:
    return PlanItem(MavCmd.NAV_RETURN_TO_LAUNCH, params=(0.0, 0.0, 0.0, 0.0), frame=FRAME_MISSION)


def upload_mission(client: FlightClient, items: list[PlanItem], timeout_s: float = 10.0) -> None:
    """Upload `items` as the mission; FlightError unless the vehicle answers MAV_MISSION_ACCEPTED."""
    start = len(client.seen.mission)
    sent: set[int] = set()

    def answered() -> bool:
        for msg in client.seen.mission[start:]:
            if msg.get_type() in ("MISSION_REQUEST_INT", "MISSION_REQUEST") and msg.seq not in sent:
                sent.add(msg.seq)
                _send_item(client, msg.seq, items[msg.seq])
        return any(m.get_type() == "MISSION_ACK" for m in client.seen.mission[start:])

    client.send(client.mav.mission_count_encode(*client.target, len(items), 0))
    client.wait(answered, timeout_s, "the mission upload")
    ack = next(m for m in client.seen.mission[start:] if m.get_type() == "MISSION_ACK")
    if ack.type != MAV_MISSION_ACCEPTED:
        raise FlightError(f"Mission upload refused: MAV_MISSION_RESULT {ack.type}.")


def _send_item(client: FlightClient, seq: int, item: PlanItem) -> None:
    x, y = (round(item.lat_deg * 1e7), round(item.lon_deg * 1e7)) if item.frame != FRAME_MISSION else (0, 0)
    client.send(client.mav.mission_item_int_encode(*client.target, seq, item.frame, item.command, 0, 1, *item.params,
                                                   x, y, item.alt_m, 0))


def start_mission(client: FlightClient, first_item: int = 0) -> None:
    """MISSION_START: the vehicle arms (if needed) and flies the mission from `first_item`."""
    result = client.command(MavCmd.MISSION_START, first_item, first_item)
    if result != MavResult.ACCEPTED:
        raise FlightError(f"MISSION_START was refused: {MavResult(result).name}.")


def wait_reached(client: FlightClient, seq: int, timeout_s: float) -> float:
    """Wait for MISSION_ITEM_REACHED of item `seq` (or a later one: the vehicle reports only the latest when two are
    reached at once); returns the time waited."""
    return client.wait(lambda: any(s >= seq for s in client.seen.reached), timeout_s, f"item {seq} reached")
