"""Runners read a link only when its socket has data, and still answer a datagram at the first tick after it arrives.

One look at the sockets per tick (SocketWatch) replaces a recvfrom per link per tick; these tests show that nothing a
client sends is missed or delayed by it: in lockstep, in real time waking every tick, and in real time with batched
ticks; and that the watch behaves the same on each kind of selector (epoll on Linux, kqueue on macOS, poll, select).
"""

from __future__ import annotations

import selectors
import statistics
import threading
import time

import pytest
from support.fakes import Client, FakeVehicle, Harness

from sitl_emu.px4 import MavCmd
from sitl_emu.runtime.node import READ_API, READ_GCS
from sitl_emu.runtime.runner import RealTimeRunner, SocketWatch
from sitl_emu.runtime.swarm import SwarmRunner
from sitl_emu.testing.sim import Sim

PROTOCOL_VERSION = 300


# The selectors this host has besides its default (epoll here; kqueue on macOS, which Linux cannot run): the watch must
# behave the same on each, so `serve` and joyfly behave the same on every OS.
SELECTORS = [name for name in ("DefaultSelector", "PollSelector", "SelectSelector") if hasattr(selectors, name)]


@pytest.fixture(params=SELECTORS)
def selector_kind(request, monkeypatch):
    monkeypatch.setattr(selectors, "DefaultSelector", getattr(selectors, request.param))
    return request.param


def test_the_watch_names_the_node_and_link_with_data_until_it_is_read(selector_kind):
    first, second = Harness(FakeVehicle()), Harness(FakeVehicle(sysid=2))
    watch = SocketWatch([first.node, second.node])
    try:
        assert watch.ready() == {}
        second.gcs.heartbeat()
        assert watch.ready() == {1: READ_GCS}
        assert watch.ready() == {1: READ_GCS}  # level-triggered: still waiting, still reported
        second.api.heartbeat()
        assert watch.ready() == {1: READ_API | READ_GCS}
        assert second.node.step_io(0, READ_GCS) == 1
        assert watch.ready() == {1: READ_API}
        assert second.node.step_io(0, READ_API) == 1
        assert watch.ready() == {}
    finally:
        watch.close()
        first.close()
        second.close()


def test_a_wait_shorter_than_a_millisecond_is_not_rounded_up_to_one(selector_kind):
    """High --speed sleeps 0.1-1 ms between ticks; epoll and poll count their timeouts in whole milliseconds, so the
    watch must wait such short times another way or a vehicle at --speed 10 would run at a fraction of it."""
    h = Harness(FakeVehicle())
    watch = SocketWatch([h.node])
    try:
        waits = []
        for _ in range(40):
            start = time.perf_counter()
            assert watch.ready(0.0002) == {}
            waits.append(time.perf_counter() - start)
    finally:
        watch.close()
        h.close()
    assert statistics.median(waits) < 0.0008  # rounded up, every wait would take at least 1 ms


def test_a_datagram_ends_a_wait_at_once(selector_kind):
    h = Harness(FakeVehicle())
    watch = SocketWatch([h.node])
    try:
        threading.Timer(0.05, h.gcs.heartbeat).start()
        start = time.monotonic()
        assert watch.ready(2.0) == {0: READ_GCS}
        assert time.monotonic() - start < 1.0
        h.node.step_io(0)
        assert watch.ready(0.0005) == {}  # read: a short wait finds nothing
    finally:
        watch.close()
        h.close()


def test_step_io_reads_only_the_links_named_and_by_default_both():
    h = Harness(FakeVehicle())
    try:
        h.api.command_long(MavCmd.COMPONENT_ARM_DISARM, 1)
        h.gcs.command_long(MavCmd.COMPONENT_ARM_DISARM, 0)
        assert h.node.step_io(0, READ_GCS) == 1
        assert [c.params[0] for c in h.vehicle.commands] == [0.0]
        assert h.node.step_io(0, 0) == 0  # told nothing waits: the API command stays in its socket
        assert h.node.step_io(0) == 1
        assert [c.params[0] for c in h.vehicle.commands] == [0.0, 1.0]
    finally:
        h.close()


def test_lockstep_answers_each_vehicle_at_the_first_tick_after_the_command():
    with Sim(count=2) as sim:
        client = Client()
        client.target = sim.ports(1).gcs
        sim.run_for(0.1)
        client.command_long(MavCmd.REQUEST_MESSAGE, PROTOCOL_VERSION, target=(2, 1))
        sim.run_for(0.004)  # one tick
        acks = [(m.get_srcSystem(), m.result) for m in client.drain() if m.get_type() == "COMMAND_ACK"]
        client.close()
    assert acks == [(2, 0)]


def _ack_wall_s(runner: RealTimeRunner, h: Harness) -> float:
    """Wall seconds from sending a command to its COMMAND_ACK while `runner` runs in a thread."""
    thread = threading.Thread(target=runner.run, daemon=True)
    thread.start()
    try:
        time.sleep(0.3)
        h.gcs.drain()
        sent = time.monotonic()
        h.gcs.command_long(MavCmd.REQUEST_MESSAGE, PROTOCOL_VERSION)
        while time.monotonic() - sent < 3.0:
            if any(m.get_type() == "COMMAND_ACK" for m in h.gcs.drain()):
                return time.monotonic() - sent
            time.sleep(0.001)
        return float("inf")
    finally:
        runner.stop()
        thread.join(timeout=5)


@pytest.mark.parametrize("runner_class", [RealTimeRunner, SwarmRunner])
def test_a_command_wakes_a_batching_runner_at_once(runner_class):
    h = Harness(FakeVehicle())
    try:
        runner = runner_class([h.node], speed=1.0)
        runner.min_wake_s = 0.5  # ticks in batches every half second...
        assert _ack_wall_s(runner, h) < 0.25  # ...but a command is answered as soon as it arrives
    finally:
        h.close()


@pytest.mark.slow
def test_batched_ticks_keep_simulated_time_with_fewer_wake_ups():
    h = Harness(FakeVehicle())
    try:
        runner = RealTimeRunner([h.node], speed=1.0)
        runner.min_wake_s = 0.05
        start = time.monotonic()
        runner.run(duration_s=1.0)
        wall = time.monotonic() - start
    finally:
        h.close()
    assert runner.steps == 250 and h.vehicle.time_us == 1_000_000
    assert wall > 0.9  # real time, not as fast as possible
    assert runner.iterations < 125  # ~20 wake-ups (a busy machine adds a few), not one per 4 ms tick (250)


def test_serve_batches_in_simulated_ms_but_wakes_at_most_1000_times_a_second():
    from sitl_emu.cli.main import DEFAULT_BATCH_MS, wake_period_s

    assert wake_period_s(DEFAULT_BATCH_MS, 1.0) == pytest.approx(0.010)  # 100 wake-ups a second at real time
    assert wake_period_s(DEFAULT_BATCH_MS, 5.0) == pytest.approx(0.002)  # still 10 simulated ms at --speed 5
    assert wake_period_s(DEFAULT_BATCH_MS, 60.0) == pytest.approx(0.001)  # floor: 1000 a second
    assert wake_period_s(0.0, 60.0) == 0.0  # --batch-ms 0: every tick, at any speed


class _StallingVehicle(FakeVehicle):
    """A vehicle whose step at `stall_at_us` blocks the host for `stall_s` of wall time (a paused VM, a GC storm)."""

    stall_at_us: int = 40_000
    stall_s: float = 0.8

    def step(self) -> None:
        super().step()
        if self.time_us == self.stall_at_us:
            time.sleep(self.stall_s)


@pytest.mark.parametrize("swarm", [False, True], ids=["single", "swarm"])
@pytest.mark.slow
def test_after_a_host_stall_the_runner_drops_the_lost_time_and_keeps_real_time_again(swarm):
    h = Harness(_StallingVehicle())
    try:
        runner = (SwarmRunner if swarm else RealTimeRunner)([h.node], speed=1.0)
        samples: list[tuple[float, int]] = []
        runner.hooks.append(lambda: samples.append((time.monotonic(), h.vehicle.time_us)))
        runner.run(duration_s=1.6)
        assert 0.2e6 <= runner.dropped_us <= 0.5e6  # 0.8 s stall, 0.5 s of it may be caught up
        after = [(t, us) for t, us in samples if us >= 1_000_000]  # well after the stall, once caught up
        (t0, us0), (t1, us1) = after[0], after[-1]
        assert us1 - us0 >= 400_000
        assert (us1 - us0) / 1e6 <= 1.5 * (t1 - t0) + 0.02  # paced by the wall clock again, not racing ahead
    finally:
        h.close()


class _HiccupVehicle(_StallingVehicle):
    """A scheduler hiccup of 30 ms wall time: at --speed 100, three simulated seconds."""

    stall_at_us: int = 400_000
    stall_s: float = 0.03


def test_at_high_speed_a_short_hiccup_is_caught_up_not_dropped():
    # The lag limit was 0.5 s of simulated time, 5 ms of wall time at x100: any hiccup longer than that lost simulated
    # time for good, and serve's vehicle ran slower than asked (the loopback flight at --speed 100).
    h = Harness(_HiccupVehicle())
    try:
        runner = RealTimeRunner([h.node], speed=100.0)
        runner.run(duration_s=6.0)
        assert runner.dropped_us == 0
        assert h.vehicle.time_us >= 6_000_000
    finally:
        h.close()
