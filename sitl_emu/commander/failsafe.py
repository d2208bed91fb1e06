"""Which mode is in force when the user's mode cannot run: PX4's mode fallbacks, reduced to what SITL needs.

After src/modules/commander/failsafe/failsafe.cpp (checkModeFallback, fromOffboardLossActParam,
fromNavDllOrRclActParam) and failsafe/framework.cpp (notifyUser: "Failsafe activated", clear conditions):
- mode fallbacks act at once (no COM_FAIL_ACT_T hold); the manual-control loss action holds first
  (commander/manual_control.py), and a manual mode left without sticks is its business, not a fallback's;
- OFFBOARD without a fresh signal -> COM_OBL_RC_ACT; a Position/Altitude/Stabilized fallback without manual control
  (the SITL norm) becomes NAV_RCL_ACT (default Return);
- a fallback mode that cannot run degrades further: Position -> Altitude -> Stabilized -> NAV_RCL_ACT,
  Hold/Return/Takeoff -> Land -> Descend;
- the fallback clears as soon as the user's mode can run again (WhenConditionClears), and an explicit mode change
  by the user ends it (the new mode can run, or the change was refused);
- flight termination (DO_FLIGHTTERMINATION) holds TERMINATION while armed;
- a geofence breach acts as GF_ACTION says (commander/geofence_failsafe.py), ranked with the others;
- a warning (Action::Warn: GF_ACTION 1, or a geofence Return while the user lands) keeps the user's mode and is no
  failsafe (vehicle_status.failsafe stays false, PX4 #22879); when it is the worst action and new, the user is told
  with an event only ("Failsafe warning:"; no "Failsafe activated" since PX4 #24858).
Each action keeps its cause (failsafe.cpp causedBy: manual-control loss, GCS connection loss, the battery level;
everything else is generic), and a Hold before a delayed action knows the action it waits for: the Decision carries
both, for notifyUser's event (events/failsafe_notices.py).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

from sitl_emu.commander.arming import CheckInputs, Req, can_run
from sitl_emu.commander.fault_failsafes import FaultFailsafes, FaultFlags, FaultSettings
from sitl_emu.commander.geofence_failsafe import GeofenceFailsafe
from sitl_emu.commander.manual_control import ManualLossFailsafe, ManualLossSettings
from sitl_emu.events.failsafe_notices import (
    ACTION_WARN,
    CAUSE_GCS_CONNECTION_LOSS,
    CAUSE_GENERIC,
    CAUSE_MANUAL_CONTROL_LOSS,
)
from sitl_emu.navigator.geofence import GeofenceResult
from sitl_emu.px4 import NavState


@dataclass(slots=True)
class Decision:
    """The mode in force and what to do, every commander cycle; read-only by convention (see ARCHITECTURE.md, On
    the tick path)."""

    nav_state: NavState
    failsafe: bool
    disarm: bool = False
    activated: bool = False  # the action got worse at this update: tell the user `text`
    text: str = ""
    # what notifyUser tells with it: failsafe_action_t, the delayed action (during its Hold), failsafe_cause_t
    action: int = 0
    delayed_action: int = 0
    cause: int = 0
    delay_s: int = 0

    def __init__(self, nav_state: NavState, failsafe: bool, disarm: bool = False, activated: bool = False,
                 text: str = "", action: int = 0, delayed_action: int = 0, cause: int = 0, delay_s: int = 0) -> None:
        self.nav_state = nav_state
        self.failsafe = failsafe
        self.disarm = disarm
        self.activated = activated
        self.text = text
        self.action = action
        self.delayed_action = delayed_action
        self.cause = cause
        self.delay_s = delay_s


# COM_OBL_RC_ACT: 0 Position, 1 Altitude, 2 Stabilized (Manual), 3 Return, 4 Land, 5 Hold, 6 Terminate, 7 Disarm
_OBL_ACTIONS: Final[dict[int, NavState | None]] = {
    0: NavState.POSCTL, 1: NavState.ALTCTL, 2: NavState.STAB, 3: NavState.AUTO_RTL, 4: NavState.AUTO_LAND,
    5: NavState.AUTO_LOITER, 6: NavState.TERMINATION, 7: None,
}
# NAV_RCL_ACT / NAV_DLL_ACT: 1 Hold, 2 Return, 3 Land, 5 Terminate, 6 Disarm (0 "disabled" falls back to Hold)
_RCL_ACTIONS: Final[dict[int, NavState | None]] = {
    0: NavState.AUTO_LOITER, 1: NavState.AUTO_LOITER, 2: NavState.AUTO_RTL, 3: NavState.AUTO_LAND,
    4: NavState.AUTO_LAND, 5: NavState.TERMINATION, 6: None,
}
_MANUAL_CHAIN: Final = (NavState.POSCTL, NavState.ALTCTL, NavState.STAB)
_AUTO_CHAIN: Final = (NavState.AUTO_LAND, NavState.DESCEND)


@dataclass(frozen=True, slots=True)
class FallbackSettings:
    obl_rc_act: int  # COM_OBL_RC_ACT
    rcl_act: int  # NAV_RCL_ACT


def _initial_fallback(user: NavState, s: FallbackSettings) -> NavState | None:
    """The first fallback for a user mode that cannot run; None means disarm."""
    if user is NavState.OFFBOARD:
        return _OBL_ACTIONS.get(s.obl_rc_act, NavState.POSCTL)
    if user in (NavState.POSITION_SLOW, NavState.POSCTL):
        return NavState.ALTCTL
    if user in (NavState.ALTCTL, NavState.ALTITUDE_CRUISE):
        return NavState.STAB
    if user in (NavState.STAB, NavState.MANUAL, NavState.ACRO):
        return _RCL_ACTIONS.get(s.rcl_act, NavState.AUTO_RTL)
    return NavState.AUTO_LAND


def resolve_fallback(user: NavState, s: FallbackSettings, inputs: CheckInputs) -> NavState | None:
    """Walk the fallback chain until a mode can run; None means disarm (DESCEND needs only an attitude)."""
    mode = _initial_fallback(user, s)
    for _ in range(8):  # every chain ends in DESCEND, TERMINATION or disarm within a few steps
        if mode is None or mode in (NavState.TERMINATION, NavState.DESCEND) or can_run(mode, inputs):
            return mode
        if mode in _MANUAL_CHAIN:
            idx = _MANUAL_CHAIN.index(mode)
            if idx + 1 < len(_MANUAL_CHAIN):
                mode = _MANUAL_CHAIN[idx + 1]
            else:  # manual control lost: the RC-loss action
                mode = _RCL_ACTIONS.get(s.rcl_act, NavState.AUTO_RTL)
        elif mode in _AUTO_CHAIN:
            mode = _AUTO_CHAIN[_AUTO_CHAIN.index(mode) + 1]
        else:
            mode = NavState.AUTO_LAND
    return NavState.DESCEND


# framework.cpp's order of actions, the worst wins: fallbacks to Position < Altitude < Stabilized < Hold < Return <
# Land < Descend < Disarm < Terminate
_RANK: Final[dict[NavState, int]] = {
    NavState.POSCTL: 2, NavState.ALTCTL: 3, NavState.STAB: 4, NavState.AUTO_LOITER: 5, NavState.AUTO_RTL: 6,
    NavState.AUTO_LAND: 7, NavState.DESCEND: 8, NavState.TERMINATION: 10,
}
_WARN_RANK: Final = ACTION_WARN  # framework.h Action::Warn: no mode of its own
_DISARM_RANK: Final = 9
_HOLD_RANK: Final = _RANK[NavState.AUTO_LOITER]
FAILSAFE_TEXT: Final = "Failsafe activated"

# an action in force: (rank, mode, disarm, cause); rank 0: none, the user's mode. The rank is framework.h's Action.
_Action = tuple[int, NavState, bool, int]


def _worse(current: _Action, user: NavState, wanted: NavState | None, disarm: bool,
           cause: int = CAUSE_GENERIC) -> _Action:
    """Combine one source's want with the action so far: disarming beats every mode (keeping the user's mode),
    otherwise the higher-ranked mode wins; a source that wants nothing (None, no disarm) changes nothing."""
    if disarm:
        return (_DISARM_RANK, user, True, cause) if current[0] < _DISARM_RANK else current
    if wanted is not None and _RANK[wanted] > current[0]:
        return _RANK[wanted], wanted, False, cause
    return current


class Failsafe:
    """Decides the nav_state in force from the user's intention, what can run, and the manual-control loss action.

    Two kinds of failsafe, combined as framework.cpp does (the worst action wins):
    - mode fallbacks: the user's mode cannot run (no offboard signal, no manual control...): at once;
    - the manual-control loss action (commander/manual_control.py): after the COM_FAIL_ACT_T Hold.
    The user is told when the action in force gets worse: "Failsafe activated" (or "... entering Hold for N seconds"
    when the Hold before a delayed action begins)."""

    def __init__(self) -> None:
        self.active = False
        self.manual_loss = ManualLossFailsafe()
        self.faults = FaultFailsafes()  # link loss, battery, failure detector (commander/fault_failsafes.py)
        self.geofence = GeofenceFailsafe()
        self._rank = 0  # the action in force (0: none)
        self._calm = Decision(NavState.MANUAL, False)  # the last no-failsafe decision (_no_failsafe)
        # the last answer of _user_mode_can_run, and what it was for
        self._can_run: tuple[NavState, CheckInputs | None, bool] = (NavState.MANUAL, None, False)

    def reset(self, *, user_mode_change: bool = False) -> None:
        """Arming, disarming or a user mode change ends every failsafe action (a mode change during the
        manual-control loss action is the user's takeover, manual_control.py)."""
        self.active = False
        self._rank = 0
        self.manual_loss.reset(user_mode_change=user_mode_change)
        self.faults.reset()
        self.geofence.reset()

    def update(self, *, armed: bool, user: NavState, inputs: CheckInputs, settings: FallbackSettings,
               terminated: bool = False, now_us: int = 0, manual_lost: bool = False,
               manual_loss: ManualLossSettings | None = None,
               faults: FaultFlags | None = None, fault_settings: FaultSettings | None = None,
               geofence: GeofenceResult | None = None, fail_act_us: int = 0) -> Decision:
        """The mode in force for the user's mode `user`, given what the checks see (`inputs`)."""
        if not armed:
            self.reset()
            return self._no_failsafe(user)
        if terminated:
            return self._decide(NavState.TERMINATION, False, "")
        action: _Action = (0, user, False, CAUSE_GENERIC)
        # framework.cpp modeCanRun leaves the manual-control requirement to the manual-control loss failsafe (with
        # its Hold first): for the user's own mode, missing sticks are not a reason to fall back at once
        if not self._user_mode_can_run(user, inputs):
            fallback = resolve_fallback(user, settings, inputs)
            action = _worse(action, user, fallback, fallback is None)
        if manual_loss is not None:
            wanted = self.manual_loss.update(now_us, manual_lost, user, manual_loss)
            action = _worse(action, user, wanted, self.manual_loss.disarm, CAUSE_MANUAL_CONTROL_LOSS)
        if faults is not None and fault_settings is not None:  # two arguments: a tuple would be built every cycle
            for want in self.faults.wanted(now_us, user, faults, fault_settings):
                action = _worse(action, user, want.mode, want.disarm, want.cause)
        if geofence is not None:
            action = self._geofence(now_us, geofence, user, fail_act_us, action)
        rank, mode, disarm, cause = action
        if rank <= _WARN_RANK:
            return self._warn_or_none(user, rank, cause)
        hold_s, delayed = 0, 0
        if mode is NavState.AUTO_LOITER:
            hold_s, delayed, cause = self._delayed(now_us, cause)
        text = f"{FAILSAFE_TEXT}: entering Hold for {hold_s} seconds" if hold_s > 0 else FAILSAFE_TEXT
        decision = self._decide(mode, disarm, text if rank > self._rank else "", (rank, delayed, cause, hold_s))
        self._rank = rank
        return decision

    def _user_mode_can_run(self, user: NavState, inputs: CheckInputs) -> bool:
        """can_run for the user's mode, leaving out the sticks (see update); worked out again only for another mode
        or other inputs: the commander shares one read-only CheckInputs while its values stay the same."""
        mode, checked, answer = self._can_run
        if user is not mode or inputs is not checked:
            answer = can_run(user, inputs, ignoring=Req.MANUAL)
            self._can_run = (user, inputs, answer)
        return answer

    def _no_failsafe(self, user: NavState) -> Decision:
        """The user's mode, no failsafe: one Decision kept while the user's mode stays (a Decision is read-only), not
        a new one every commander cycle."""
        if self._calm.nav_state is not user:
            self._calm = Decision(user, False)
        return self._calm

    def _delayed(self, now_us: int, cause: int) -> tuple[int, int, int]:
        """(seconds of Hold left, the action it delays, that action's cause) for the Hold before a delayed action;
        (0, 0, cause) for a Hold that is the action itself. The worst delayed action wins, as its cause."""
        holds = ((self.manual_loss, CAUSE_MANUAL_CONTROL_LOSS), (self.faults.dll, CAUSE_GCS_CONNECTION_LOSS),
                 (self.faults.battery, self.faults.battery.cause), (self.geofence, CAUSE_GENERIC))
        hold_s, delayed = 0, 0
        for source, source_cause in holds:
            left = source.hold_s(now_us)
            hold_s = max(hold_s, left)
            if left > 0 and source.action is not None and _RANK[source.action] > delayed:
                delayed, cause = _RANK[source.action], source_cause
        return hold_s, (delayed if hold_s > 0 else 0), cause

    def _warn_or_none(self, user: NavState, rank: int, cause: int) -> Decision:
        """No action, or only a warning: the user's mode, no failsafe; a new warning is told (no text)."""
        self.active = False
        told = rank > self._rank
        self._rank = rank
        if rank == 0:
            return self._no_failsafe(user)
        return Decision(user, False, activated=told, action=ACTION_WARN, cause=cause)

    def _geofence(self, now_us: int, result: GeofenceResult, user: NavState, fail_act_us: int,
                  current: _Action) -> _Action:
        """The geofence_breached failsafe joins the others: the worse action wins (a warning beats no action)."""
        worse_than_hold = self._rank > _HOLD_RANK
        wanted = self.geofence.update(now_us, result, user, fail_act_us, worse_than_hold)
        if self.geofence.warns and current[0] < _WARN_RANK:
            return _WARN_RANK, user, False, CAUSE_GENERIC
        return _worse(current, user, wanted, False)

    def _decide(self, nav_state: NavState, disarm: bool, text: str,
                notice: tuple[int, int, int, int] = (0, 0, 0, 0)) -> Decision:
        self.active = True
        return Decision(nav_state, True, disarm, bool(text), text, *notice)
