"""Which mode is in force when the user's mode cannot run: PX4's mode fallbacks, reduced to what SITL needs.

After src/modules/commander/failsafe/failsafe.cpp (checkModeFallback, fromOffboardLossActParam,
fromNavDllOrRclActParam) and failsafe/framework.cpp (notifyUser: "Failsafe activated", clear conditions):
- mode fallbacks act at once (no COM_FAIL_ACT_T hold);
- OFFBOARD without a fresh signal -> COM_OBL_RC_ACT; a Position/Altitude/Stabilized fallback without manual control
  (the SITL norm) becomes NAV_RCL_ACT (default Return);
- a fallback mode that cannot run degrades further: Position -> Altitude -> Stabilized -> NAV_RCL_ACT,
  Hold/Return/Takeoff -> Land -> Descend;
- the fallback clears as soon as the user's mode can run again (WhenConditionClears), and an explicit mode change
  by the user ends it (the new mode can run, or the change was refused);
- flight termination (DO_FLIGHTTERMINATION) holds TERMINATION while armed.
"""

from __future__ import annotations

from dataclasses import dataclass

from sitl_emu.flight.arming import CheckInputs, can_run
from sitl_emu.px4 import NavState


@dataclass(slots=True)
class Decision:
    """The mode in force and what to do (made every commander cycle, so not frozen and with its __init__ written
    out, as arming.CheckInputs). Treat it as read-only."""

    nav_state: NavState
    failsafe: bool
    disarm: bool = False
    activated: bool = False  # the failsafe started at this update: say "Failsafe activated"

    def __init__(self, nav_state: NavState, failsafe: bool, disarm: bool = False, activated: bool = False) -> None:
        self.nav_state = nav_state
        self.failsafe = failsafe
        self.disarm = disarm
        self.activated = activated


# COM_OBL_RC_ACT: 0 Position, 1 Altitude, 2 Stabilized (Manual), 3 Return, 4 Land, 5 Hold, 6 Terminate, 7 Disarm
_OBL_ACTIONS: dict[int, NavState | None] = {
    0: NavState.POSCTL, 1: NavState.ALTCTL, 2: NavState.STAB, 3: NavState.AUTO_RTL, 4: NavState.AUTO_LAND,
    5: NavState.AUTO_LOITER, 6: NavState.TERMINATION, 7: None,
}
# NAV_RCL_ACT / NAV_DLL_ACT: 1 Hold, 2 Return, 3 Land, 5 Terminate, 6 Disarm (0 "disabled" falls back to Hold)
_RCL_ACTIONS: dict[int, NavState | None] = {
    0: NavState.AUTO_LOITER, 1: NavState.AUTO_LOITER, 2: NavState.AUTO_RTL, 3: NavState.AUTO_LAND,
    4: NavState.AUTO_LAND, 5: NavState.TERMINATION, 6: None,
}
_MANUAL_CHAIN = (NavState.POSCTL, NavState.ALTCTL, NavState.STAB)
_AUTO_CHAIN = (NavState.AUTO_LAND, NavState.DESCEND)


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


class Failsafe:
    """Decides the nav_state in force from the user's intention and what can run."""

    def __init__(self) -> None:
        self.active = False

    def reset(self) -> None:
        self.active = False

    def update(self, *, armed: bool, user: NavState, inputs: CheckInputs, settings: FallbackSettings,
               terminated: bool = False) -> Decision:
        """The mode in force for the user's mode `user`, given what the checks see (`inputs`)."""
        if not armed:
            self.active = False
            return Decision(user, False)
        if terminated:
            return self._enter(NavState.TERMINATION)
        if can_run(user, inputs):
            self.active = False
            return Decision(user, False)
        fallback = resolve_fallback(user, settings, inputs)
        if fallback is None:
            decision = self._enter(user)
            return Decision(user, True, disarm=True, activated=decision.activated)
        return self._enter(fallback)

    def _enter(self, nav_state: NavState) -> Decision:
        activated = not self.active
        self.active = True
        return Decision(nav_state, True, activated=activated)
