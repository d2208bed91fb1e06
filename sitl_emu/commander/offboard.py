"""OFFBOARD: what keeps it alive, and what happens when the setpoints stop.

The story, end to end (PX4: offboardCheck.cpp, mode_requirements.cpp, failsafe.cpp checkModeFallback):
1. Every accepted SET_POSITION_TARGET_* / SET_ATTITUDE_TARGET (mavlink/receiver.py, mavlink/setpoints.py) becomes an
   offboard_control_mode plus a setpoint: `Vehicle.offboard_input` refreshes the `OffboardSignal` below in ANY mode,
   and hands the setpoint to the mode executor (flight_tasks/mode_executor.py), which flies it only in OFFBOARD.
2. The signal is fresh while a setpoint kind is set and the last one is younger than COM_OF_LOSS_T (1 s). Without a
   fresh signal OFFBOARD cannot run (commander/arming.py): switching to it while armed is refused, and arming in it is
   refused ("No offboard signal"); while disarmed the switch is accepted, as PX4 does.
3. Setpoints stop in flight: the signal goes stale, OFFBOARD can no longer run, and the failsafe (commander/failsafe.py)
   puts COM_OBL_RC_ACT's fallback in force at once ("Failsafe activated"): without manual control Position cannot
   run either, so NAV_RCL_ACT decides, Return by default. The user's intention stays OFFBOARD.
4. Setpoints come back: the signal is fresh again and, the intention still being OFFBOARD, the vehicle returns to
   OFFBOARD by itself; any explicit mode change by the user ends that.
"""

from __future__ import annotations

from sitl_emu.types import OffboardControlMode


class OffboardSignal:
    """The COM_OF_LOSS_T watchdog over offboard_control_mode (offboardCheck.cpp)."""

    __slots__ = ("_last_us", "mode")

    def __init__(self) -> None:
        self._last_us: int | None = None
        self.mode: OffboardControlMode | None = None  # the kinds of the last offboard message

    def refresh(self, now_us: int, mode: OffboardControlMode) -> None:
        """An offboard_control_mode arrived (in any mode)."""
        self._last_us = now_us
        self.mode = mode

    def fresh(self, now_us: int, loss_us: int) -> bool:
        """A setpoint kind is set and now < timestamp + COM_OF_LOSS_T."""
        if self._last_us is None or self.mode is None or not self.mode.any():
            return False
        return now_us < self._last_us + loss_us
