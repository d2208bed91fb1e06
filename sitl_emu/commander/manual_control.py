"""Manual control: a MAVLink joystick's sticks as the vehicle's RC, present while they keep arriving.

The story (PX4: mavlink_receiver.cpp handle_message_manual_control, src/modules/manual_control/ManualControl.cpp,
ManualControlSelector.cpp, commander's manual-control checks):
1. Every MANUAL_CONTROL for our system becomes a `ManualControlSetpoint` (mavlink/receiver.py); `Vehicle.
   manual_control_input` hands it to `ManualControlSignal.refresh` below, whatever the mode.
2. COM_RC_IN_MODE says which sources count: 1 (SITL's default, MAVLink only), 2 and 3 (RC and/or MAVLink) and 5-8
   (RC and MAVLink by priority; the emulator has no RC, so MAVLink wins) take it, 0 (RC only) and 4 (stick input
   disabled) ignore it.
3. The input is valid while the last setpoint is younger than COM_RC_LOSS_T; manual modes (POSCTL, ALTCTL,
   STABILIZED...) need it to run (commander/arming.py Req.MANUAL), and the flight tasks read its sticks.
4. The stream stops while armed (`ManualLossFailsafe` below): NAV_RCL_ACT (Return by default) after holding for
   COM_FAIL_ACT_T ("Failsafe activated: entering Hold for 5 seconds", then "Failsafe activated"), in every mode
   but those COM_RCL_EXCEPT excepts, and not at all if the vehicle was armed without manual control. Sticks coming
   back do not end it: a mode change or disarming does (failsafe.cpp: clear condition OnModeChangeOrDisarm).
5. A mode the user selects during that Hold or action (Hold, Return, Land) is a takeover (framework.cpp
   getSelectedAction: a user-intended mode update makes the action a warning): the mode runs although the sticks
   are still gone, and the failsafe comes back only with a new loss, after the sticks returned. So MAVSDK-Python's
   manual_control example (one MANUAL_CONTROL, arm, take off) takes off even when the loss is noticed first.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

from sitl_emu.px4 import NavState
from sitl_emu.types import ManualControlSetpoint

# COM_RC_IN_MODE values whose input includes MAVLink MANUAL_CONTROL (commander_params.yaml / manual_control_params)
_MAVLINK_SOURCES: Final = frozenset({1, 2, 3, 5, 6, 7, 8})
INPUT_DISABLED: Final = 4  # COM_RC_IN_MODE 4: stick input disabled
# manual_control's 200 ms timer notices a stream that stopped: the loss shows at the first timer run past
# COM_RC_LOSS_T (ManualControl.cpp ScheduleDelayed(200_ms)), 0.6 s after the last sample with the default 0.5 s
LOSS_POLL_US: Final = 200_000
CENTRED: Final = ManualControlSetpoint(throttle=0.0)


class ManualControlSignal:
    """The COM_RC_LOSS_T watchdog over manual_control_setpoint, and the last sticks."""

    __slots__ = ("_last_us", "ever_received", "setpoint")

    def __init__(self) -> None:
        self._last_us: int | None = None
        self.setpoint: ManualControlSetpoint = CENTRED
        self.ever_received = False

    def refresh(self, now_us: int, setpoint: ManualControlSetpoint, in_mode: int) -> bool:
        """A MANUAL_CONTROL arrived; False if COM_RC_IN_MODE ignores MAVLink input."""
        if in_mode not in _MAVLINK_SOURCES:
            return False
        self._last_us = now_us
        self.setpoint = setpoint
        self.ever_received = True
        return True

    def valid(self, now_us: int, loss_us: int) -> bool:
        """Some input arrived and manual_control has not yet seen it time out (COM_RC_LOSS_T, polled every 200 ms)."""
        if self._last_us is None:
            return False
        polls = loss_us // LOSS_POLL_US + 1  # the first 200 ms poll that finds the input older than the timeout
        return now_us < self._last_us + polls * LOSS_POLL_US


@dataclass(frozen=True, slots=True)
class ManualLossSettings:
    rcl_act: int  # NAV_RCL_ACT: 1 Hold, 2 Return, 3 Land, 5 Terminate, 6 Disarm; others no action
    rcl_except: int  # COM_RCL_EXCEPT bits: 0 Mission, 1 Auto modes, 2 Offboard
    fail_act_us: int  # COM_FAIL_ACT_T
    input_disabled: bool  # COM_RC_IN_MODE 4


# NAV_RCL_ACT -> the action's mode (None: disarm)
_RCL_ACTIONS: Final[dict[int, NavState | None]] = {
    1: NavState.AUTO_LOITER, 2: NavState.AUTO_RTL, 3: NavState.AUTO_LAND, 5: NavState.TERMINATION, 6: None,
}
_AUTO_MODES: Final = frozenset({NavState.AUTO_LOITER, NavState.AUTO_TAKEOFF, NavState.AUTO_VTOL_TAKEOFF,
                                NavState.AUTO_LAND, NavState.AUTO_RTL, NavState.DESCEND,
                                NavState.AUTO_FOLLOW_TARGET, NavState.AUTO_PRECLAND, NavState.ORBIT,
                                NavState.GUIDED_COURSE})
_DELAYABLE: Final = frozenset({NavState.AUTO_RTL, NavState.AUTO_LAND, NavState.DESCEND})


def loss_ignored(user: NavState, rcl_except: int) -> bool:
    """failsafe.cpp isFailsafeIgnored: the modes COM_RCL_EXCEPT excepts (manual modes never are)."""
    if user is NavState.AUTO_MISSION:
        return bool(rcl_except & 1)
    if user in _AUTO_MODES:
        return bool(rcl_except & 2)
    if user is NavState.OFFBOARD:
        return bool(rcl_except & 4)
    return False


class ManualLossFailsafe:
    """The manual_control_signal_lost failsafe: which action, and the COM_FAIL_ACT_T Hold before it.

    `update` returns the mode the failsafe wants now: AUTO_LOITER during the delay, then the action's mode; None if
    it wants nothing; `disarm` says the action is to disarm. The action is kept once started until `reset()`
    (arming, disarming, a user mode change)."""

    def __init__(self) -> None:
        self.action: NavState | None = None
        self.disarm = False
        self._active = False
        self._hold_until_us = 0
        self._taken_over = False  # the user changed mode during this loss: no action until the next loss

    def reset(self, *, user_mode_change: bool = False) -> None:
        """End the action (arming, disarming, a user mode change). A user mode change while an action that allows
        it (anything but disarm and termination) is in force is a takeover (framework.cpp actionAllowsUserTakeover)."""
        if not user_mode_change:
            self._taken_over = False
        elif self._active and not self.disarm and self.action is not NavState.TERMINATION:
            self._taken_over = True
        self.action, self.disarm, self._active, self._hold_until_us = None, False, False, 0

    def update(self, now_us: int, lost: bool, user: NavState, s: ManualLossSettings) -> NavState | None:
        if not lost:
            self._taken_over = False  # the next loss is a new failsafe (checkFailsafe adds the action again)
        if (not self._active and lost and not self._taken_over and not s.input_disabled
                and not loss_ignored(user, s.rcl_except)):
            self._start(now_us, user, s)
        if not self._active or (self.action is None and not self.disarm):
            return None
        if now_us < self._hold_until_us:
            return NavState.AUTO_LOITER
        return self.action

    def hold_s(self, now_us: int) -> int:
        """Whole seconds of Hold left before the action (0: not holding); PX4 rounds the delay in its text."""
        if not self._active or now_us >= self._hold_until_us:
            return 0
        return round((self._hold_until_us - now_us) / 1e6)

    def _start(self, now_us: int, user: NavState, s: ManualLossSettings) -> None:
        if s.rcl_act not in _RCL_ACTIONS:
            return  # 0 / 7 / other: no failsafe action
        action = _RCL_ACTIONS[s.rcl_act]
        if action is NavState.AUTO_RTL and user in (NavState.AUTO_LAND, NavState.AUTO_RTL):
            return  # framework.cpp: already landing or returning, a Return is only a warning
        self._active = True
        self.action, self.disarm = action, action is None
        if action in _DELAYABLE and s.fail_act_us > 100_000:
            self._hold_until_us = now_us + s.fail_act_us
