"""The failsafes of faults: ground-station link loss, low battery, and the failure detector's attitude check.

The commander's Failsafe (commander/failsafe.py) asks `FaultFailsafes.wanted` every cycle for the modes these sources
want, and the worst action wins, as framework.cpp combines them. Sources (src/modules/commander/failsafe/):
- GCS connection loss (failsafe.cpp, gcs_connection_lost): NAV_DLL_ACT (0 disabled, 1 Hold, 2 Return, 3 Land,
  5 Terminate, 6 Disarm) after the COM_FAIL_ACT_T Hold, not in the modes COM_DLL_EXCEPT excepts nor in Land;
  cleared by a mode change or disarming (the same machinery as manual-control loss: commander/manual_control.py);
- battery warning (commander/battery.py): COM_LOW_BAT_ACT at critical / emergency, the Hold first on the first action;
- failure detector (fd_critical_failure, roll or pitch beyond FD_FAIL_R / FD_FAIL_P for FD_FAIL_R_TTRI /
  FD_FAIL_P_TTRI): disarm during the first COM_SPOOLUP_TIME + 3 s after arming, else terminate unless the
  CBRK_FLIGHTTERM circuit breaker is set (121212, PX4's default), then only a warning.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

from sitl_emu.commander.battery import WARNING_NONE, battery_action
from sitl_emu.commander.manual_control import ManualLossFailsafe, ManualLossSettings
from sitl_emu.events.failsafe_notices import CAUSE_BATTERY_OFFSET, CAUSE_GCS_CONNECTION_LOSS, CAUSE_GENERIC
from sitl_emu.params import ParamRegistry
from sitl_emu.px4 import NavState

CBRK_FLIGHTTERM_KEY: Final = 121212
EARLY_TAKEOFF_US: Final = 3_000_000  # failsafe.cpp: the early takeoff phase, spool-up + 3 s
_DELAYABLE: Final = frozenset({NavState.AUTO_RTL, NavState.AUTO_LAND, NavState.DESCEND})


@dataclass(slots=True)
class FaultFlags:
    """PX4's failsafe_flags the faults set (written by the vehicle's fault monitor, read by the commander)."""

    gcs_connection_lost: bool = False
    battery_warning: int = WARNING_NONE
    battery_warning_at_arming: int = WARNING_NONE
    position_lost: bool = False  # no horizontal position estimate (GPS off, dead reckoning timed out)
    fd_critical_failure: bool = False
    armed_at_us: int = 0


@dataclass(frozen=True, slots=True)
class FaultSettings:
    dll: ManualLossSettings  # NAV_DLL_ACT, COM_DLL_EXCEPT, COM_FAIL_ACT_T
    low_bat_act: int  # COM_LOW_BAT_ACT
    fail_act_us: int  # COM_FAIL_ACT_T
    flight_termination_allowed: bool  # CBRK_FLIGHTTERM != 121212
    spoolup_us: int  # COM_SPOOLUP_TIME

    @classmethod
    def from_params(cls, p: ParamRegistry) -> FaultSettings:
        fail_act_us = int(float(p["COM_FAIL_ACT_T"]) * 1e6)
        return cls(ManualLossSettings(int(p["NAV_DLL_ACT"]), int(p["COM_DLL_EXCEPT"]), fail_act_us, False),
                   int(p["COM_LOW_BAT_ACT"]), fail_act_us, int(p["CBRK_FLIGHTTERM"]) != CBRK_FLIGHTTERM_KEY,
                   int(float(p["COM_SPOOLUP_TIME"]) * 1e6))


@dataclass(frozen=True, slots=True)
class Want:
    """What one source wants now: a mode (AUTO_LOITER during its Hold), or to disarm."""

    mode: NavState | None
    disarm: bool = False
    cause: int = CAUSE_GENERIC


class BatteryFailsafe:
    """The battery action in force, kept until reset (the warning never falls while armed)."""

    def __init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        self.action: NavState | None = None
        self.cause = CAUSE_GENERIC
        self._hold_until_us = 0
        self._held = False

    def update(self, now_us: int, flags: FaultFlags, s: FaultSettings) -> NavState | None:
        action = battery_action(flags.battery_warning, s.low_bat_act, flags.battery_warning_at_arming)
        if action is not None and action is not self.action:
            if not self._held and action in _DELAYABLE and s.fail_act_us > 100_000:
                self._hold_until_us, self._held = now_us + s.fail_act_us, True  # the Hold comes once
            self.action, self.cause = action, flags.battery_warning + CAUSE_BATTERY_OFFSET
        if self.action is None:
            return None
        return NavState.AUTO_LOITER if now_us < self._hold_until_us else self.action

    def hold_s(self, now_us: int) -> int:
        return round((self._hold_until_us - now_us) / 1e6) if now_us < self._hold_until_us else 0


class FaultFailsafes:
    """All fault sources together; `reset` on arming, disarming and a user mode change."""

    def __init__(self) -> None:
        self.dll = ManualLossFailsafe()
        self.battery = BatteryFailsafe()

    def reset(self) -> None:
        self.dll.reset()
        self.battery.reset()

    def wanted(self, now_us: int, user: NavState, flags: FaultFlags, s: FaultSettings) -> list[Want]:
        wants: list[Want] = []
        lost = flags.gcs_connection_lost and user not in (NavState.AUTO_LAND, NavState.AUTO_PRECLAND)
        dll = self.dll.update(now_us, lost, user, s.dll)
        if self.dll.disarm:
            wants.append(Want(None, disarm=True, cause=CAUSE_GCS_CONNECTION_LOSS))
        elif dll is not None:
            wants.append(Want(dll, cause=CAUSE_GCS_CONNECTION_LOSS))
        bat = self.battery.update(now_us, flags, s)
        if bat is not None:
            wants.append(Want(bat, cause=self.battery.cause))
        if flags.fd_critical_failure:
            if now_us < flags.armed_at_us + s.spoolup_us + EARLY_TAKEOFF_US:
                wants.append(Want(None, disarm=True))
            elif s.flight_termination_allowed:
                wants.append(Want(NavState.TERMINATION))
        return wants

    def hold_s(self, now_us: int) -> int:
        return max(self.dll.hold_s(now_us), self.battery.hold_s(now_us))
