"""Bounded command retries that explain a refusal with the vehicle's own words (COMMAND_ACK result + STATUSTEXT),
and the plan joyfly carries out when it exits (--on-exit)."""

from __future__ import annotations

import math
from collections.abc import Callable
from enum import Enum

from joyfly.link.vehicle_link import CommandHandle, VehicleLink, VehicleState
from px4common.modes import AutoSubMode, MainMode

# PX4 publishes the refusal STATUSTEXT in the same commander cycle as the ACK, but STATUSTEXT is a 20 Hz stream
# (px4-behaviour.md 1.4), so the text may trail the ACK by up to 50 ms: wait a little before explaining.
REASON_GRACE_S = 0.25
WARNING = 4  # MAV_SEVERITY_WARNING: CRITICAL "Arming denied: ..." and friends are below it
MAV_LANDED_STATE_ON_GROUND = 1


class Outcome(Enum):
    """What a retried command came to, when there is news (`last_refusal` says why)."""

    REFUSED = "refused"  # refused (or accepted without effect); it will be sent again
    FAILED = "failed"  # refused and the attempts are used up
    DONE = "done"  # the exit plan only: the vehicle is where --on-exit puts it


class Retry:
    """Send a command until the vehicle's state shows it worked, at most `attempts` times.

    `update()` returns None while in progress, REFUSED after a refusal that will be retried, FAILED when the
    attempts are used up. An ACCEPTED whose effect does not show within `settle_s` counts as a new attempt.
    """

    def __init__(self, what: str, attempts: int, now_s: float, settle_s: float = 2.0, pause_s: float = 1.0) -> None:
        self.what = what
        self.attempts = attempts
        self.settle_s = settle_s
        self.pause_s = pause_s
        self.attempt = 0
        self.handle: CommandHandle | None = None
        self.sent_s = now_s
        self.next_try_s = now_s
        self.accepted_s: float | None = None
        self.refused_s: float | None = None
        self.last_refusal = ""

    def update(self, now_s: float, link: VehicleLink, send: Callable[[], CommandHandle],
               done: Callable[[], bool]) -> Outcome | None:
        if done():
            return None
        if self.handle is None:
            return self._maybe_send(now_s, send)
        if not self.handle.done:
            return None
        if self.handle.accepted:
            return self._after_accept(now_s)
        return self._after_refusal(now_s, link)

    def _maybe_send(self, now_s: float, send: Callable[[], CommandHandle]) -> Outcome | None:
        if now_s < self.next_try_s:
            return None
        if self.attempt >= self.attempts:
            return Outcome.FAILED
        self.attempt += 1
        self.handle = send()
        self.sent_s = now_s
        return None

    def _after_accept(self, now_s: float) -> Outcome | None:
        if self.accepted_s is None:
            self.accepted_s = now_s
        if now_s - self.accepted_s > self.settle_s:
            self.handle, self.accepted_s = None, None
            self.last_refusal = f"{self.what}: the vehicle accepted but its state did not change"
            return Outcome.REFUSED if self.attempt < self.attempts else Outcome.FAILED
        return None

    def _after_refusal(self, now_s: float, link: VehicleLink) -> Outcome | None:
        if self.refused_s is None:
            self.refused_s = now_s
        if now_s - self.refused_s < REASON_GRACE_S:
            return None
        assert self.handle is not None
        self.last_refusal = f"{self.what} refused by the vehicle ({self.handle.describe()}): {self._reason(link)}."
        if self.handle.timed_out:
            self.last_refusal = f"{self.what}: no answer from the vehicle."
        self.handle, self.refused_s = None, None
        self.next_try_s = now_s + self.pause_s
        return Outcome.REFUSED if self.attempt < self.attempts else Outcome.FAILED

    def _reason(self, link: VehicleLink) -> str:
        texts = [t for t in link.statustexts if t.time_s >= self.sent_s - 0.05]
        serious = [t.text for t in texts if t.severity <= WARNING]
        chosen = serious or [t.text for t in texts]
        return "; ".join(dict.fromkeys(chosen)) if chosen else "the vehicle gave no reason"

    def failure_message(self) -> str:
        return f"{self.what} failed after {self.attempt} attempt(s). {self.last_refusal}"


EXIT_MODES = {"land": "AUTO.LAND", "rtl": "AUTO.RTL", "hold": "AUTO.LOITER"}  # where each --on-exit puts PX4


class ExitPlan:
    """--on-exit: NAV_LAND (land), NAV_RETURN_TO_LAUNCH (rtl) or DO_SET_MODE AUTO.LOITER (hold), retried on refusal,
    until the vehicle is disarmed (land, rtl) or out of joyfly's mode (hold: `in_control`, OFFBOARD by default).
    A vehicle armed on the ground (before its take-off, or after landing in a manual mode; or an ARM on its way) is
    disarmed at once, as a pilot would: LAND there would only wait for PX4's auto-disarm (COM_DISARM_PRFLT, 10 s).
    The disarm is a plain ARM_DISARM, which PX4 refuses in the air ("Disarming denied: not landed",
    Commander::disarm): if the vehicle lifted off meanwhile, the --on-exit action follows. The caller enforces the
    overall timeout."""

    def __init__(self, on_exit: str, link: VehicleLink, now_s: float,
                 in_control: Callable[[VehicleState], bool] | None = None) -> None:
        self.on_exit = on_exit
        self.link = link
        self.in_control = in_control or (lambda st: st.offboard)
        self.started_s = now_s
        self.disarming = exits_by_disarming(link.state)
        what = "Disarming on the ground" if self.disarming else f"Exit action {on_exit}"
        self.retry = Retry(what, 1 if self.disarming else 3, now_s, settle_s=math.inf)
        self._gave_up = False

    @property
    def commanded_mode(self) -> str | None:
        """The mode the vehicle is in once it ACCEPTED the exit command (PX4 ACKs after switching), else None."""
        handle = self.retry.handle
        accepted = handle is not None and handle.accepted and not self.disarming
        return EXIT_MODES.get(self.on_exit) if accepted else None

    def _send(self) -> CommandHandle:
        if self.disarming:
            return self.link.arm(False)
        if self.on_exit == "land":
            return self.link.land()
        if self.on_exit == "rtl":
            return self.link.return_to_launch()
        return self.link.set_mode(MainMode.AUTO, AutoSubMode.LOITER)

    def done(self) -> bool:
        """Out of joyfly's mode (hold), or disarmed by a HEARTBEAT sent since the exit began (an ARM just sent may not
        show in the 1 Hz HEARTBEAT yet)."""
        st = self.link.state
        if self.on_exit == "hold" and not self.disarming:
            return not self.in_control(st)
        return not st.armed and st.last_heartbeat_s is not None and st.last_heartbeat_s > self.started_s

    def update(self, now_s: float) -> Outcome | None:
        """DONE; a refusal to report (`retry.last_refusal`), FAILED only once; or None while in progress."""
        if self.done():
            return Outcome.DONE
        outcome = self.retry.update(now_s, self.link, self._send, lambda: False)
        if self.disarming and outcome is not None:  # refused: it is flying after all, so the --on-exit action
            self.disarming = False
            self.retry = Retry(f"Exit action {self.on_exit}", 3, now_s, settle_s=math.inf)
            return None
        if outcome is Outcome.FAILED:
            if self._gave_up:
                return None
            self._gave_up = True
        return outcome


def exits_by_disarming(st: VehicleState) -> bool:
    """On the ground by the vehicle's own land detector (EXTENDED_SYS_STATE landed_state ON_GROUND), or not yet
    armed by its HEARTBEAT (an ARM on its way): there the exit disarms."""
    return st.landed_state == MAV_LANDED_STATE_ON_GROUND or (st.landed_state == 0 and not st.armed)
