"""The flight session's watchdogs on its clock: the link (lost, back: `Change`) and the joystick (lost, back, lost
too long). The session steps that act on them are in joyfly/session/watch.py."""

from __future__ import annotations

from enum import Enum

BACK_WAIT_S = 2.0  # PX4 stamps ATTITUDE (15-100 Hz) with its boot time from its first seconds on


class Change(Enum):
    """What a watchdog saw change since its last update."""

    LOST = "lost"
    BACK = "back"


class LinkWatch:
    """Reports LOST once the heartbeat watchdog fails and BACK when it recovers.

    After a loss, "back" also waits (at most BACK_WAIT_S) for a message stamped with the vehicle's time since boot,
    so that a vehicle that restarted is known as such (its boot time went back) before anyone says it is back.
    """

    def __init__(self) -> None:
        self.ok = False
        self.lost_s: float | None = None
        self._beats_s: float | None = None  # when heartbeats came back after the loss

    def update(self, heartbeat_ok: bool, now_s: float = 0.0, stamped_s: float | None = None) -> Change | None:
        if not heartbeat_ok:
            self._beats_s = None
        elif self._beats_s is None:
            self._beats_s = now_s
        ok = heartbeat_ok and (self.ok or self._boot_time_fresh(now_s, stamped_s))
        if ok == self.ok:
            return None
        self.ok = ok
        self.lost_s = None if ok else now_s
        return Change.BACK if ok else Change.LOST

    def _boot_time_fresh(self, now_s: float, stamped_s: float | None) -> bool:
        if self.lost_s is None:  # the first connection
            return True
        if stamped_s is not None and stamped_s > self.lost_s:
            return True
        return self._beats_s is not None and now_s - self._beats_s >= BACK_WAIT_S


class JoystickWatch:
    """Tracks a lost joystick: LOST/BACK on changes, `expired()` once after `timeout_s` lost."""

    def __init__(self, timeout_s: float) -> None:
        self.timeout_s = timeout_s
        self.lost_since: float | None = None
        self._fired = False

    @property
    def lost(self) -> bool:
        return self.lost_since is not None

    def update(self, connected: bool, now_s: float) -> Change | None:
        if connected and self.lost_since is not None:
            self.lost_since = None
            self._fired = False
            return Change.BACK
        if not connected and self.lost_since is None:
            self.lost_since = now_s
            return Change.LOST
        return None

    def expired(self, now_s: float) -> bool:
        if self.lost_since is None or self._fired or now_s - self.lost_since < self.timeout_s:
            return False
        self._fired = True
        return True
