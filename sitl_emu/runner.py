"""Runners: the only code that reads the wall clock or sleeps.

A runner advances each node's vehicle in fixed steps of simulated time and calls `node.step_io(now_us)` after each
step (and whenever a datagram arrives), so streams, heartbeats and timeouts all follow simulated time.
`RealTimeRunner(speed)` keeps simulated time at `speed` x wall time and sleeps in select() on the sockets, so incoming
commands are answered without waiting for the next step. `run_lockstep()` steps as fast as possible, for tests.
"""

from __future__ import annotations

import logging
import select
import threading
import time
from collections.abc import Callable, Sequence
from typing import Any

log = logging.getLogger(__name__)

MAX_LAG_US = 500_000  # if the host stalls longer than this, drop the lost time instead of fast-forwarding through it


class RealTimeRunner:
    """Run nodes at `speed` x real time until `stop()` (thread-safe) or KeyboardInterrupt."""

    def __init__(self, nodes: Sequence[Any], speed: float = 1.0,
                 hooks: Sequence[Callable[[], None]] = ()) -> None:
        if not speed > 0:
            raise ValueError("speed must be a positive number")
        self.nodes = list(nodes)
        self.speed = float(speed)
        self.hooks = list(hooks)
        self._stop = threading.Event()
        self.iterations = 0
        self.steps = 0
        self.dropped_us = 0
        # Sleep at least this long between wake-ups (0: wake for every tick). Longer batches of ticks cost less CPU
        # per tick (measured: 12.8 % -> 8.7 % at 16 ms -> 6.3 % at 40 ms of a core for one hovering vehicle);
        # telemetry then leaves in bursts (each message still stamped at its own tick); input wakes us at once.
        self.min_wake_s = 0.0

    def stop(self) -> None:
        self._stop.set()

    @property
    def stopped(self) -> bool:
        return self._stop.is_set()

    def run(self, duration_s: float | None = None) -> None:
        """Run until stopped, or for `duration_s` of simulated time."""
        lead = self.nodes[0].vehicle
        dt_us = int(lead.dt_us)
        start_sim_us = int(lead.time_us)
        end_us = None if duration_s is None else start_sim_us + int(duration_s * 1e6)
        start_wall = time.monotonic()
        fds = [fd for node in self.nodes for fd in node.filenos()]
        while not self._stop.is_set():
            target_us = start_sim_us + int((time.monotonic() - start_wall) * 1e6 * self.speed)
            if end_us is not None:
                target_us = min(target_us, end_us)
            start_sim_us, target_us = self._limit_lag(start_sim_us, target_us, lead)
            before_us = int(lead.time_us)
            self._advance(target_us, dt_us)
            if lead.time_us < before_us:  # rebooted: simulated time restarted at 0, so does the wall-clock anchor
                start_sim_us, start_wall = int(lead.time_us), time.monotonic()
            for hook in self.hooks:
                hook()
            self.iterations += 1
            if end_us is not None and lead.time_us >= end_us:
                break
            next_wall = start_wall + (lead.time_us + dt_us - start_sim_us) / 1e6 / self.speed
            timeout = max(0.0, next_wall - time.monotonic())
            if timeout > 0:
                _wait_readable(fds, max(timeout, self.min_wake_s))

    def _limit_lag(self, start_sim_us: int, target_us: int, lead: Any) -> tuple[int, int]:
        lag = target_us - int(lead.time_us)
        if lag > MAX_LAG_US:
            skipped = lag - MAX_LAG_US
            if self.dropped_us == 0:
                log.warning("cannot keep up with --speed %g: simulated time falls behind the wall clock", self.speed)
            self.dropped_us += skipped
            return start_sim_us + skipped, target_us - skipped
        return start_sim_us, target_us

    def _advance(self, target_us: int, dt_us: int) -> None:
        stepped = False
        for node in self.nodes:
            vehicle = node.vehicle
            for _ in range(max(0, (target_us - int(vehicle.time_us)) // dt_us)):
                before_us = vehicle.time_us
                vehicle.step()
                node.step_io(vehicle.time_us)
                self.steps += 1
                stepped = True
                if vehicle.time_us < before_us:  # rebooted: time restarted, the caller re-anchors
                    break
        if not stepped:  # woken by a datagram between steps: answer it now
            for node in self.nodes:
                node.step_io(node.vehicle.time_us)


def run_lockstep(nodes: Sequence[Any], duration_s: float, io_every_steps: int = 1) -> None:
    """Step every node as fast as possible for `duration_s` of simulated time, doing I/O every few steps."""
    for node in nodes:
        vehicle = node.vehicle
        end_us = vehicle.time_us + int(duration_s * 1e6)
        n = 0
        while vehicle.time_us < end_us:
            vehicle.step()
            n += 1
            if n % io_every_steps == 0:
                node.step_io(vehicle.time_us)


def _wait_readable(fds: list[int], timeout_s: float) -> None:
    try:
        select.select(fds, [], [], timeout_s)
    except (OSError, ValueError):  # a socket closed under us during shutdown
        time.sleep(min(timeout_s, 0.01))
