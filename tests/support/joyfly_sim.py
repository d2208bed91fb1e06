"""joyfly's session in simulated time, for tests: a clock whose sleep advances at once, and an in-memory transport
pair standing in for UDP (the session reads time and bytes only through these two protocols)."""

from __future__ import annotations

import collections
from collections.abc import Callable


class SimClock:
    """Simulated time: `sleep` advances `now` at once and runs the registered hooks.

    Hooks (`on_advance(now_s)`) let a test step a simulated vehicle in lockstep with the session. A sleep longer
    than `max_step_s` is cut into steps of at most that length, so hooks see a fine-grained time line.
    """

    def __init__(self, start_s: float = 0.0, max_step_s: float = 0.01) -> None:
        self._now_s = start_s
        self._max_step_s = max_step_s
        self._hooks: list[Callable[[float], None]] = []

    def now(self) -> float:
        return self._now_s

    def on_advance(self, hook: Callable[[float], None]) -> None:
        self._hooks.append(hook)

    def sleep(self, seconds: float) -> None:
        if seconds <= 0:
            return
        target = self._now_s + seconds
        while self._now_s < target:
            self._now_s = min(target, self._now_s + self._max_step_s)
            for hook in self._hooks:
                hook(self._now_s)



class MemoryTransport:
    """One end of an in-memory pair: what one end writes, the other reads. Never waits (simulated time)."""

    def __init__(self, description: str = "memory") -> None:
        self.description = description
        self.inbox: collections.deque[bytes] = collections.deque()
        self.peer: MemoryTransport | None = None
        self.closed = False

    def write(self, data: bytes) -> None:
        if self.peer is not None and not self.closed:
            self.peer.inbox.append(bytes(data))

    def read(self, timeout_s: float) -> bytes:
        return self.inbox.popleft() if self.inbox else b""

    def close(self) -> None:
        self.closed = True


def memory_pair() -> tuple[MemoryTransport, MemoryTransport]:
    a, b = MemoryTransport("memory:a"), MemoryTransport("memory:b")
    a.peer, b.peer = b, a
    return a, b
