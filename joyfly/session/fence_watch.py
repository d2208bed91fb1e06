"""joyfly's fence, watched: the vehicle outside it (a breach), how deep and for how long, and when --fence-action is
due. A pure tracker on the session's clock, like the joystick and link watchdogs (joyfly/session/watchdogs.py); the
session step that warns and acts on it is in joyfly/session/watch.py.

joyfly keeps its own setpoints (and, in Position/Altitude mode, the sticks it sends) inside the fence, so a vehicle
outside it is one that cannot follow them: wind stronger than it can fight, a gust, a vehicle taken over elsewhere.
joyfly says so at once. The action waits until the vehicle has been outside FENCE_GRACE_S and is not coming back
(closer to the fence by RETURN_M_S x RETURN_WINDOW_S over the last RETURN_WINDOW_S): joyfly's setpoint already pulls it
back, a gust may carry it out for a moment, and PX4 itself drifts out of a small fence while it takes off in wind
(PX4 SIH in a steady 8 m/s wind: 11 m downwind while PX4 allows only MPC_TILTMAX_LND of tilt, back within 13 s:
px4-recorded-facts.md 1). A vehicle carried away, or held outside by the wind, is acted upon after the grace time.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from enum import Enum

FENCE_ACTIONS = ("warn", "hold", "rtl", "land")
# Further outside than this is a breach: a vehicle braking at the fence may overshoot it by a few decimetres (PX4's
# position step response overshoots ~3%: reference px4-traces b_xy_step), one following the fence in a gusty crosswind
# lags by about a metre, and a GPS position wanders by about as much
FENCE_TOLERANCE_M = 1.0
FENCE_GRACE_S = 5.0  # outside this long (in one breach), and not coming back, and --fence-action acts
RETURN_WINDOW_S = 2.0
RETURN_M_S = 0.25  # coming back: the breach shrank at least this fast over the last RETURN_WINDOW_S


class FenceChange(Enum):
    OUT = "out"
    BACK = "back"


@dataclass(frozen=True, slots=True)
class Breach:
    """The breach under way: since when, and the deepest it went (metres outside the fence)."""

    since_s: float
    depth_m: float
    deepest_m: float


class FenceWatch:
    """Feed it the fence margin (negative outside) each tick while the vehicle flies; it reports OUT at a new breach,
    BACK when the vehicle is inside again, and `due()` once per breach, after FENCE_GRACE_S outside, when the vehicle
    is not coming back."""

    def __init__(self, grace_s: float = FENCE_GRACE_S, tolerance_m: float = FENCE_TOLERANCE_M) -> None:
        self.grace_s, self.tolerance_m = grace_s, tolerance_m
        self.breach: Breach | None = None
        self.count = 0
        self.deepest_m = 0.0  # over the whole session
        self._acted = False
        self._recent: deque[tuple[float, float]] = deque()  # (time, depth) over the last RETURN_WINDOW_S

    @property
    def acted(self) -> bool:
        """--fence-action was due in the breach under way."""
        return self._acted

    def update(self, margin_m: float | None, now_s: float) -> FenceChange | None:
        """`margin_m` None: nothing to judge (on the ground, no position, no home yet): a breach under way ends."""
        outside = margin_m is not None and margin_m < -self.tolerance_m
        if not outside:
            was_out, self.breach = self.breach is not None, None
            self._recent.clear()
            return FenceChange.BACK if was_out and margin_m is not None else None
        assert margin_m is not None
        depth = -margin_m
        self.deepest_m = max(self.deepest_m, depth)
        self._recent.append((now_s, depth))
        while now_s - self._recent[0][0] > RETURN_WINDOW_S:
            self._recent.popleft()
        if self.breach is None:
            self.breach, self._acted = Breach(now_s, depth, depth), False
            self.count += 1
            return FenceChange.OUT
        self.breach = Breach(self.breach.since_s, depth, max(self.breach.deepest_m, depth))
        return None

    @property
    def coming_back(self) -> bool:
        """The breach shrank by RETURN_M_S x RETURN_WINDOW_S over the last RETURN_WINDOW_S."""
        if not self._recent:
            return False
        (first_s, first_m), (last_s, last_m) = self._recent[0], self._recent[-1]
        return last_s - first_s >= 0.9 * RETURN_WINDOW_S and first_m - last_m >= RETURN_M_S * RETURN_WINDOW_S

    def due(self, now_s: float) -> bool:
        """True once per breach: outside for the grace time, and not coming back."""
        if (self.breach is None or self._acted or now_s - self.breach.since_s < self.grace_s
                or self.coming_back):
            return False
        self._acted = True
        return True

    def reset(self) -> None:
        """Forget the breach under way (the vehicle restarted: its frame is new); the counts stay."""
        self.breach, self._acted = None, False
        self._recent.clear()


def breach_alert(watch: FenceWatch, action: str, acting: bool, now_s: float) -> str:
    """The dashboard's word on the breach under way, and when --fence-action acts ("" when there is none)."""
    breach = watch.breach
    if breach is None:
        return ""
    if action == "warn" or not acting or watch.acted:
        return "BREACH"
    if watch.coming_back:
        return "BREACH: coming back"
    left_s = watch.grace_s - (now_s - breach.since_s)
    return f"BREACH: {action} in {left_s:.0f} s" if left_s > 0 else f"BREACH: {action}"


def breach_message(depth_m: float, fence_m: float, action: str, grace_s: float = FENCE_GRACE_S) -> str:
    """What joyfly says the moment the vehicle is outside the fence."""
    then = ("joyfly only warns (--fence-action warn)" if action == "warn" else
            f"--fence-action {action} acts if it stays outside for {grace_s:g} s without coming back")
    return (f"The vehicle is {depth_m:.1f} m outside the fence ({fence_m:g} m around home), where joyfly's commands "
            f"do not take it (wind stronger than it can fight?): {then}.")
