"""Runners: the only code that reads the wall clock or sleeps.

A runner advances each node's vehicle in fixed steps of simulated time and calls `node.step_io(now_us, readable)`
after each step (and whenever a datagram arrives), so streams, heartbeats and timeouts all follow simulated time.
`RealTimeRunner(speed)` keeps simulated time at `speed` x wall time and sleeps in a selector on the sockets, so incoming
commands are answered without waiting for the next step. In-process lockstep (as fast as possible) is
`sitl_emu.testing.sim.Sim`.

Which links have data waiting comes from one `SocketWatch.ready()` per tick over every socket (the wake-up's own
look serves the first tick after it), so an idle link costs no system call: before, each node tried a recvfrom on
both links every tick (two syscalls per vehicle per tick, nearly always EAGAIN).
"""

from __future__ import annotations

import logging
import select
import selectors
import threading
import time
from collections.abc import Callable, Sequence

from sitl_emu.runtime.node import READ_API, READ_GCS, VehicleNode
from sitl_emu.runtime.timeline import Timeline

log = logging.getLogger(__name__)

# If the host stalls longer than this, drop the lost time instead of fast-forwarding through it: 0.5 s of simulated
# time, or of wall time above --speed 1. In simulated time alone the limit was 5 ms of wall time at --speed 100, and a
# scheduler hiccup that short made serve drop time for good (measured: the loopback flight's vehicle ran at x47 of
# x100 on a busy 2-core machine, although the server needs under a core at x100).
MAX_LAG_US = 500_000


def lag_limit_us(speed: float) -> int:
    """The simulated time a runner at `speed` may fall behind before it drops the rest (MAX_LAG_US)."""
    return round(MAX_LAG_US * max(1.0, speed))

FINE_TIMEOUT_S = 0.002  # below this a wait uses select() (µs resolution), not epoll's or poll's whole ms
# the selectors whose timeout is counted in whole milliseconds (kqueue's and select()'s are not)
_MS_TIMEOUT_SELECTORS = tuple(getattr(selectors, name) for name in ("EpollSelector", "DevpollSelector", "PollSelector")
                              if hasattr(selectors, name))
NOTHING_READY: dict[int, int] = {}  # ready()'s answer when no socket has data (shared: never mutate it)


class SocketWatch:
    """Which nodes have datagrams waiting, and on which links: one selector over all their sockets.

    `ready(timeout_s)` returns {node index: READ_API | READ_GCS bits} for the nodes with data, waiting up to
    `timeout_s` for the first datagram (0: just look). Level-triggered: a link that a read budget left with data is
    reported again next time. The selector is the OS's best (selectors.DefaultSelector: epoll on Linux, kqueue on
    macOS and the BSDs). epoll and poll time out in whole milliseconds, rounded up; with them a short wait (high
    --speed) goes through select() (µs resolution) instead, on the selector's own descriptor where it has one (epoll:
    one fd however many sockets), else on the sockets. A datagram wakes the runner at once either way.
    """

    def __init__(self, nodes: Sequence[VehicleNode]) -> None:
        self._selector = selectors.DefaultSelector()
        for index, node in enumerate(nodes):
            for bit, fd in zip((READ_API, READ_GCS), node.filenos(), strict=True):
                self._selector.register(fd, selectors.EVENT_READ, (index, bit))
        self._fine_wait_fds = _fine_wait_fds(self._selector)

    def ready(self, timeout_s: float = 0.0) -> dict[int, int]:
        try:
            if 0 < timeout_s < FINE_TIMEOUT_S and self._fine_wait_fds:  # the selector would round up to 1 ms
                select.select(self._fine_wait_fds, (), (), timeout_s)
                timeout_s = 0.0
            events = self._selector.select(timeout_s)
        except (OSError, ValueError):  # a socket (or the watch) closed under us during shutdown
            time.sleep(min(timeout_s, 0.01))
            return NOTHING_READY
        if not events:  # the common case, every tick: no dict built
            return NOTHING_READY
        ready: dict[int, int] = {}
        for key, _ in events:
            index, bit = key.data
            ready[index] = ready.get(index, 0) | bit
        return ready

    def close(self) -> None:
        self._selector.close()


def _fine_wait_fds(selector: selectors.BaseSelector) -> list[int]:
    """What to select() on for waits under FINE_TIMEOUT_S; empty if the selector's own timeout is fine enough."""
    if not isinstance(selector, _MS_TIMEOUT_SELECTORS):
        return []  # kqueue and select() take the timeout in µs
    fileno = getattr(selector, "fileno", None)  # epoll, /dev/poll: readable when a registered socket is
    return [fileno()] if fileno is not None else list(selector.get_map())


class RealTimeRunner:
    """Run nodes at `speed` x real time until `stop()` (thread-safe) or KeyboardInterrupt."""

    def __init__(self, nodes: Sequence[VehicleNode], speed: float = 1.0,
                 hooks: Sequence[Callable[[], None]] = ()) -> None:
        if not speed > 0:
            raise ValueError("speed must be a positive number")
        self.nodes = list(nodes)
        self.speed = float(speed)
        self.hooks = list(hooks)
        self._stop = threading.Event()
        self.iterations = 0
        self.dropped_us = 0
        self.timeline = Timeline(self.nodes)  # the one tick loop (runtime/timeline.py); it never goes back
        # Sleep at least this long (wall time) between wake-ups and run the ticks due in one batch; 0 wakes for every
        # tick. Each wake-up costs more CPU than most ticks (cold caches), so batches save CPU; telemetry then leaves
        # in bursts (each message still stamped at its own tick) and a datagram still wakes us at once. `serve` sets
        # it from --batch-ms (cli/main.py DEFAULT_BATCH_MS); library users (tests, joyfly demo) wake every tick.
        self.min_wake_s = 0.0
        self._watch: SocketWatch | None = None

    def stop(self) -> None:
        self._stop.set()

    @property
    def stopped(self) -> bool:
        return self._stop.is_set()

    def run(self, duration_s: float | None = None) -> None:
        """Run until stopped, or for `duration_s` of simulated time."""
        self._watch = SocketWatch(self.nodes)
        try:
            self._run(duration_s, self._watch)
        finally:
            self._watch.close()
            self._watch = None

    @property
    def steps(self) -> int:
        """Vehicle ticks run so far, all vehicles together."""
        return self.timeline.steps

    @property
    def timeline_us(self) -> int:
        """Simulated time since this runner was created; unlike a vehicle's own time it never restarts."""
        return self.timeline.time_us

    def _run(self, duration_s: float | None, watch: SocketWatch) -> None:
        """Run until stopped, or for `duration_s` more of simulated time (run() opens `watch`)."""
        timeline = self.timeline
        dt_us = timeline.dt_us
        anchor_us, start_wall = timeline.time_us, time.monotonic()  # simulated time `anchor_us` at wall `start_wall`
        end_us = None if duration_s is None else anchor_us + round(duration_s * 1e6)
        ready: dict[int, int] | None = None  # None: not known, look before the first tick
        stop = self._stop
        max_lag_us = lag_limit_us(self.speed)
        while not stop.is_set():
            woke = time.monotonic()
            target_us = anchor_us + int((woke - start_wall) * 1e6 * self.speed)
            if end_us is not None and end_us < target_us:
                target_us = end_us
            lag_us = target_us - timeline.time_us
            if lag_us > max_lag_us:  # the host cannot keep up: drop the lost time rather than race through it
                skipped = lag_us - max_lag_us
                self._warn_lag(lag_us)
                anchor_us -= skipped
                target_us -= skipped
                self.dropped_us += skipped
            if not timeline.advance_to(target_us, watch.ready, ready):  # woken by a datagram between ticks
                timeline.answer(watch.ready() if ready is None else ready)
            for hook in self.hooks:
                hook()
            self.iterations += 1
            if end_us is not None and timeline.time_us >= end_us:
                break
            next_wall = start_wall + (timeline.time_us + dt_us - anchor_us) / 1e6 / self.speed
            if next_wall < woke + self.min_wake_s:  # batching: wake at a steady period, however long this batch took
                next_wall = woke + self.min_wake_s
            timeout = next_wall - time.monotonic()
            ready = watch.ready(timeout) if timeout > 0 else None

    def _warn_lag(self, lag_us: int) -> None:
        if self.dropped_us == 0:
            log.warning("cannot keep up with --speed %g: simulated time falls behind the wall clock", self.speed)
