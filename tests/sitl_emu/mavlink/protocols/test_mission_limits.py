"""The mission protocol's limits over loopback UDP (issue 14's bad input), pymavlink against a lockstep Sim:
the largest mission PX4 stores (MAX_ITEMS, 10,000 items in mavlink_mission.cpp's dataman) uploaded item by item and
one item past it refused with MAV_MISSION_NO_SPACE, the stored plan untouched; a client that vanishes after part of
an upload leaves the previous plan whole (PX4 stores a plan only at the final item), and another link uploads after
PX4's 5 s timeout. (Two links at once: test_mission_cases.py; in memory: test_mission.py.)

Run with -s to see the simulated and wall time of the 10,000-item upload.
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterator
from typing import Any

import pytest
from support.fakes import Client

from sitl_emu.navigator.mission_store import MAX_ITEMS
from sitl_emu.testing.sim import Sim

LAT, LON = 473977420, 85455940
MAV_MISSION_ACCEPTED, MAV_MISSION_ERROR, MAV_MISSION_NO_SPACE = 0, 1, 4


@pytest.fixture()
def sim() -> Iterator[Sim]:
    with Sim() as s:
        yield s


def _client(sim: Sim, gcs: bool = False, sysid: int = 255) -> Client:
    client = Client(sysid=sysid)
    client.target = sim.ports(0).gcs if gcs else sim.ports(0).api
    return client


def _item(client: Client, seq: int) -> Any:
    """A waypoint 5 m above home, its latitude stepped by `seq` (1e-7 degree) so each stored item is its own."""
    return client.mav.mission_item_int_encode(1, 1, seq, 6, 16, 0, 1, 0.0, 0.0, 0.0, math.nan, LAT + seq, LON, 5.0, 0)


def _answer(sim: Sim, client: Client, since: int, timeout_s: float = 2.0) -> tuple[Any, int]:
    """The vehicle's next MISSION_REQUEST_INT or MISSION_ACK after `since` received messages, and the count of
    received messages up to and including it."""
    found: list[tuple[Any, int]] = []

    def got() -> bool:
        client.drain()
        for i in range(since, len(client.received)):
            if client.received[i].get_type() in ("MISSION_REQUEST_INT", "MISSION_ACK"):
                found.append((client.received[i], i + 1))
                return True
        return False
    assert sim.run_until(got, timeout_s), "no answer"
    return found[0]


def _upload(sim: Sim, client: Client, count: int, stop_after: int | None = None) -> Any:
    """MISSION_COUNT, then the item each MISSION_REQUEST_INT asks for; the final MISSION_ACK, or (with
    `stop_after`) the request after that many items, the client then going silent."""
    client.drain()
    since = len(client.received)
    client.send(client.mav.mission_count_encode(1, 1, count, 0))
    sent = 0
    while True:
        msg, since = _answer(sim, client, since)
        if msg.get_type() == "MISSION_ACK" or sent == stop_after:
            return msg
        assert msg.seq == sent
        client.send(_item(client, msg.seq))
        sent += 1


@pytest.mark.slow
def test_ten_thousand_items_are_stored_and_one_more_is_no_space(sim: Sim) -> None:
    limit = MAX_ITEMS[0]
    assert limit == 10_000
    client = _client(sim)
    t_sim_us, t_wall = sim.time_us, time.perf_counter()
    ack = _upload(sim, client, limit)
    sim_s, wall_s = (sim.time_us - t_sim_us) / 1e6, time.perf_counter() - t_wall
    print(f"\n{limit} mission items uploaded over UDP in lockstep: {sim_s:.1f} s simulated, {wall_s:.1f} s wall")
    assert (ack.type, ack.mission_type) == (MAV_MISSION_ACCEPTED, 0)
    store = sim.vehicle(0).mission_store()
    plan = store.plan(0)
    assert plan.count == limit and plan.items[-1].x == LAT + limit - 1
    ack = _upload(sim, client, limit + 1)
    assert (ack.type, ack.mission_type) == (MAV_MISSION_NO_SPACE, 0)
    assert store.plan(0) is plan  # the refused upload did not touch the stored plan
    ok = _upload(sim, client, 2)  # and the vehicle is free again at once
    assert ok.type == MAV_MISSION_ACCEPTED and store.count(0) == 2


def test_a_vanished_client_leaves_the_stored_plan_whole_and_another_link_uploads_after_the_timeout(sim: Sim) -> None:
    gcs, api = _client(sim, gcs=True, sysid=254), _client(sim)
    assert _upload(sim, gcs, 3).type == MAV_MISSION_ACCEPTED
    store = sim.vehicle(0).mission_store()
    before = store.plan(0)
    request = _upload(sim, api, 5, stop_after=2)  # items 0 and 1 sent, then silence
    assert (request.get_type(), request.seq) == ("MISSION_REQUEST_INT", 2)
    busy = _upload(sim, gcs, 1)
    assert busy.type == MAV_MISSION_ERROR  # mavlink_mission.cpp: a transfer over another instance
    assert store.plan(0) is before
    assert sim.run_until(lambda: any(e.text == "Mission sync timeout" for e in sim.vehicle(0).events_after(0)), 6.0)
    assert store.plan(0) is before and store.count(0) == 3
    assert _upload(sim, gcs, 4).type == MAV_MISSION_ACCEPTED
    assert store.count(0) == 4 and [i.x for i in store.plan(0).items] == [LAT, LAT + 1, LAT + 2, LAT + 3]
