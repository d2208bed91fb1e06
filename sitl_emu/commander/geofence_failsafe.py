"""The geofence_breached failsafe: what GF_ACTION makes the commander do, and when it ends.

After src/modules/commander/failsafe/failsafe.cpp (fromGfActParam, checked with cannotBeDeferred) and framework.cpp:
- 0 None: nothing (the flag is not even raised);
- 1 Warning: Action::Warn, cleared when the breach clears (WhenConditionClears): no mode change, not a failsafe
  (vehicle_status.failsafe stays false), the user told once per breach (commander/failsafe.py: the Warn notice);
- 2 Hold: AUTO_LOITER at once ("Failsafe activated"), the user may switch modes to leave it;
- 3 Return / 5 Land: first a Hold of COM_FAIL_ACT_T when that is above 0.1 s and no worse failsafe is active
  ("Failsafe activated: entering Hold for N seconds"), then AUTO_RTL / AUTO_LAND ("Failsafe activated");
  framework.cpp getSelectedAction turns a Return (or the Hold before it) into a warning while the user lands; the
  emulator also lets a Return while the user already returns pass silently (PX4 would hold, then return again);
- 4 Terminate: TERMINATION, never cleared while armed (the commander keeps an armed vehicle in termination).
Hold, Return and Land clear on a mode change or disarming (OnModeChangeOrDisarm); a mode change while the fence is
still breached is the user taking over: the action stops and starts again only after the breach cleared and comes
back (the action stays registered while its condition holds, so it is not re-added). A GF_ACTION changed during a
breach changes the registered action (checkFailsafe updates it, keeping its delay and clear condition).
"""

from __future__ import annotations

from typing import Final

from sitl_emu.navigator.geofence import (
    GF_ACTION_HOLD,
    GF_ACTION_LAND,
    GF_ACTION_RETURN,
    GF_ACTION_TERMINATE,
    GF_ACTION_WARN,
    GeofenceResult,
)
from sitl_emu.px4 import NavState

_ACTION_MODES: Final[dict[int, NavState]] = {
    GF_ACTION_HOLD: NavState.AUTO_LOITER, GF_ACTION_RETURN: NavState.AUTO_RTL, GF_ACTION_LAND: NavState.AUTO_LAND,
    GF_ACTION_TERMINATE: NavState.TERMINATION,
}
_DELAYED: Final = frozenset({NavState.AUTO_RTL, NavState.AUTO_LAND})
_MIN_DELAY_US: Final = 100_000  # COM_FAIL_ACT_T above 0.1 s enables the Hold first


class GeofenceFailsafe:
    """`update` returns the mode the geofence failsafe wants now (AUTO_LOITER during the delay), or None; `warns`
    says whether it wants a warning instead (Action::Warn: no mode)."""

    def __init__(self) -> None:
        self.action: NavState | None = None
        self.warns = False
        self._active = False
        self._hold_until_us = 0
        self._breached = False
        self._taken_over = False
        self._fail_act_us = 0
        self._gf_action = -1

    def reset(self) -> None:
        """Arming, disarming or a user mode change: the action ends; while the breach lasts it stays taken over."""
        self.action, self._active, self._hold_until_us = None, False, 0
        self._taken_over = self._breached

    def update(self, now_us: int, result: GeofenceResult, user: NavState, fail_act_us: int,
               worse_than_hold_active: bool) -> NavState | None:
        breached = self._breached = result.breached
        self.warns = False
        if not breached:
            self._taken_over = False
            if self._active and self._gf_action == GF_ACTION_WARN:  # Warn clears with its condition
                self._active = False
        elif not self._active and not self._taken_over:
            self._start(now_us, result.action, fail_act_us, worse_than_hold_active)
        elif self._active and result.action != self._gf_action:  # checkFailsafe: the action follows GF_ACTION
            self.action, self._gf_action = _ACTION_MODES.get(result.action), result.action
        if self.action is None:
            self.warns = self._active and self._gf_action == GF_ACTION_WARN
            return None
        if self.action is NavState.AUTO_RTL and user is NavState.AUTO_LAND:
            self.warns = True  # framework.cpp: already landing, a Return (or its Hold) is only a warning
            return None
        if self.action is NavState.AUTO_RTL and user is NavState.AUTO_RTL:
            return None
        if now_us < self._hold_until_us:
            return NavState.AUTO_LOITER
        return self.action

    def sticks_may_take_over(self, now_us: int) -> bool:
        """framework.cpp allow_user_takeover: a Hold action, the delay before Return/Land, or Return/Land without a
        delay (COM_FAIL_ACT_T 0.1 s or less) let the user leave by a mode switch only, not with the sticks."""
        if self.action is None or self.action is NavState.TERMINATION:
            return True
        if self.action is NavState.AUTO_LOITER or now_us < self._hold_until_us:
            return False
        return self._fail_act_us > _MIN_DELAY_US

    def hold_s(self, now_us: int) -> int:
        """Whole seconds of Hold left before the action (0: not holding)."""
        if self.action is None or now_us >= self._hold_until_us:
            return 0
        return round((self._hold_until_us - now_us) / 1e6)

    def _start(self, now_us: int, gf_action: int, fail_act_us: int, worse_than_hold_active: bool) -> None:
        self._active = True  # Warning: registered, no mode
        self.action, self._gf_action = _ACTION_MODES.get(gf_action), gf_action
        self._fail_act_us = fail_act_us
        if self.action in _DELAYED and fail_act_us > _MIN_DELAY_US and not worse_than_hold_active:
            self._hold_until_us = now_us + fail_act_us
