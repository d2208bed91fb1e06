"""The stream scheduler sends what PX4's per-stream rate scheduling sends, in the same order, whatever the history.

The reference below is the plain algorithm (scan the stream table every pass; a stream is due when its time has come,
its next time is one interval later, or one interval from now if it fell behind; the interval is never shorter than
its source topic's period), written from the rules with a dict of due times. Streams keeps rows it rebuilds after a
change and a lazy start; the two must agree message for message through rate changes, stopped and restarted streams,
reboots and a start delay.
"""

from __future__ import annotations

import random

import pytest

from sitl_emu.mavlink.telemetry import streams as telemetry
from sitl_emu.mavlink.telemetry.streams import HEARTBEAT_ID, HEARTBEAT_INTERVAL_US, StreamMode, Streams


class _Reference:
    def __init__(self, mode: StreamMode, start_delay_us: int = 0) -> None:
        self.start_delay_us = start_delay_us
        self.starting = True
        rates = telemetry.ONBOARD_RATES_HZ if mode is StreamMode.ONBOARD else telemetry.NORMAL_RATES_HZ
        self.default = {mid: round(1e6 / hz) for mid, hz in rates.items()}
        self.interval = dict(self.default)
        self.next: dict[int, int] = {}
        self.next_hb = 0

    def set_interval(self, msg_id: int, interval_us: float) -> None:
        if interval_us < -1e-5:
            self.interval.pop(msg_id, None)
        elif interval_us <= 1e-5:
            if msg_id in self.default:
                self.interval[msg_id] = self.default[msg_id]
            else:
                self.interval.pop(msg_id, None)
        else:
            self.interval[msg_id] = max(int(interval_us), 1)
        self.next.pop(msg_id, None)

    def restart(self) -> None:
        self.next.clear()
        self.next_hb = 0
        self.starting = True

    def due(self, now: int) -> list[int]:
        if self.starting and now >= self.next_hb:  # the first pass: everything begins start_delay_us later
            self.starting = False
            if self.start_delay_us:
                self.next_hb = now + self.start_delay_us
                self.next = {msg_id: self.next_hb for msg_id in self.interval}
                return []
        out = []
        if now >= self.next_hb:
            out.append(HEARTBEAT_ID)
            self.next_hb = _next(self.next_hb, HEARTBEAT_INTERVAL_US, now)
        for msg_id, interval in self.interval.items():
            due = self.next.get(msg_id, now)
            if now >= due:  # a stream whose source topic is slower goes at the topic's pace
                self.next[msg_id] = _next(due, max(interval, telemetry.SOURCE_PERIOD_US.get(msg_id, 0)), now)
                out.append(msg_id)
        return out


def _next(due: int, interval: int, now: int) -> int:
    nxt = due + interval
    return nxt if nxt > now else now + interval


def _run(mode: StreamMode, seed: int, start_delay_us: int = 0) -> tuple[list[list[int]], list[list[int]]]:
    """(what Streams sent, what the reference sends) per pass, for a random history of passes and changes."""
    rng = random.Random(seed)
    streams, reference, now = Streams(mode, start_delay_us), _Reference(mode, start_delay_us), 0
    got, expected = [], []
    for _ in range(4000):
        now += rng.choice((1000, 4000, 4000, 4000, 25_000))
        event = rng.random()
        if event < 0.01:
            streams.restart()
            reference.restart()
            now = rng.randrange(0, 50_000)  # a reboot: time starts again
        elif event < 0.05:
            msg_id = rng.choice([*telemetry.BUILDERS, 77])
            interval = rng.choice((-1.0, 0.0, 1.0, 3000.0, 20_000.0, 250_000.0, 1.5e6))
            if streams.set_interval(msg_id, interval):
                reference.set_interval(msg_id, interval)
        got.append(streams.due(now))
        expected.append(reference.due(now))
    return got, expected


@pytest.mark.slow
def test_streams_send_what_a_table_scan_sends_through_rate_changes_and_reboots():
    for mode in StreamMode:
        for seed in range(3):
            for start_delay_us in (0, 12_000):  # a swarm's later vehicles begin streaming later (runtime/swarm.py)
                got, expected = _run(mode, seed, start_delay_us)
                assert sum(map(len, got)) > 1000
                assert got == expected


def test_a_start_delay_holds_back_every_stream_and_the_heartbeat_until_it_has_passed():
    streams = Streams(StreamMode.NORMAL, start_delay_us=8000)
    assert streams.due(100_000) == []  # the first pass
    assert streams.due(104_000) == []
    assert streams.due(108_000) == [HEARTBEAT_ID, *telemetry.NORMAL_RATES_HZ]  # all at once, in table order
