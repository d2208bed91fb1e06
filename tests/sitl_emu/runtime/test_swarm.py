"""A swarm's vehicles (sitl_emu/runtime/swarm.py) start streaming one tick apart, as PX4 instances started one after
another are out of phase, so their 1 Hz messages do not all leave in the same tick."""

from __future__ import annotations

import socket

from sitl_emu.runtime.swarm import STREAM_STAGGER_US, stream_delay_us
from sitl_emu.testing.sim import Sim


def test_vehicle_i_sends_its_first_heartbeat_i_ticks_after_the_first() -> None:
    sink = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)  # the GCS links' remote from boot (not offset)
    sink.bind(("127.0.0.1", 0))
    with sink, Sim(count=3, gcs_remote=sink.getsockname()) as sim:
        dt_us = sim.vehicle(0).dt_us
        assert dt_us == STREAM_STAGGER_US
        sent: list[list[int]] = [[] for _ in sim.nodes]  # datagrams sent per tick, per vehicle
        for tick in range(1, 30):
            before = [node.gcs.stats.tx_messages for node in sim.nodes]
            sim.advance_to(tick * dt_us)
            for i, node in enumerate(sim.nodes):
                sent[i].append(node.gcs.stats.tx_messages - before[i])
        assert [s.index(next(n for n in s if n)) for s in sent] == [0, 1, 2]  # the first datagrams
        assert sent[1][1:] == sent[0][:-1] and sent[2][2:] == sent[0][:-2]  # the same streams, later


def test_the_stagger_wraps_at_one_second() -> None:
    assert [stream_delay_us(i) for i in (0, 1, 249, 250, 251)] == [0, 4000, 996_000, 0, 4000]
