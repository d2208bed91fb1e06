"""The mode the user asked for, kept apart from the mode in force (which failsafes may override).

After src/modules/commander/UserModeIntention.cpp (v1.15-v1.17):
- a change is always allowed while disarmed (or when forced); when armed only if the mode can run;
- nothing leaves TERMINATION;
- the mode to return to after disarming is the last accepted one that does not prevent arming (TERMINATION sticks)
  and is no take-off (PX4 PR 25735: a vehicle that landed during a take-off would take off again at the next arming).
"""

from __future__ import annotations

from sitl_emu.commander.arming import mode_prevents_arming
from sitl_emu.px4 import NavState

_TAKEOFFS = (NavState.AUTO_TAKEOFF, NavState.AUTO_VTOL_TAKEOFF)


class ModeIntention:
    """User-intended nav_state and the nav_state to restore after disarming."""

    def __init__(self, boot_nav_state: NavState = NavState.AUTO_LOITER) -> None:
        # UserModeIntention.hpp: _user_intented_nav_state{AUTO_LOITER} (boot mode Hold)
        self.user_intended: NavState = boot_nav_state
        self.after_disarming: NavState = boot_nav_state

    def change(self, nav_state: NavState, *, armed: bool, can_run: bool, in_termination: bool = False,
               force: bool = False) -> bool:
        """Try to make nav_state the user's intention; return whether it was accepted."""
        allowed = force or not armed or can_run
        if in_termination:
            allowed = False
        if not allowed:
            return False
        self.user_intended = nav_state
        if (not mode_prevents_arming(nav_state) and nav_state not in _TAKEOFFS) or nav_state is NavState.TERMINATION:
            self.after_disarming = nav_state
        return True

    def on_disarm(self) -> None:
        self.user_intended = self.after_disarming
