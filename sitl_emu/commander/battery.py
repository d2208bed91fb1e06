"""The simulated battery and what PX4 makes of its charge: warning levels and the low-battery failsafe action.

- Discharge (src/modules/simulation/battery_simulator/BatterySimulator.cpp): while armed the charge falls linearly
  by 1 / SIM_BAT_DRAIN per second (at least 1 s) and never below SIM_BAT_MIN_PCT; disarmed it is full again. The
  voltage interpolates between BAT1_V_EMPTY and BAT1_V_CHARGED per cell, times BAT1_N_CELLS; no current sensor.
- State of charge and warning (src/lib/battery/battery.cpp determineWarning): with no current the voltage-based state
  of charge equals the simulated charge (PX4's filters on it are left out); below BAT_EMERGEN_THR emergency, below
  BAT_CRIT_THR critical, below BAT_LOW_THR low. The battery counts only 2 s after it appears (battery_initialized).
  While armed the warning only rises (HealthAndArmingChecks/checks/batteryCheck.cpp).
- A failure injected on the battery (failure battery off) reports remaining 0 and the emergency warning
  (src/lib/failure_injection/FailureInjection.cpp process_battery).
- The action (src/modules/commander/failsafe/failsafe.cpp fromBatteryWarningActParam), COM_LOW_BAT_ACT: 0 warning,
  2 Land, 3 Return at critical / Land at emergency, 4 Return at critical / Terminate at emergency (1, deprecated:
  Return at both). Low is only ever a warning; an action only if the warning is worse than at arming.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

from sitl_emu.params import ParamRegistry
from sitl_emu.px4 import NavState

WARNING_NONE: Final = 0  # battery_status_s::WARNING_*
WARNING_LOW: Final = 1
WARNING_CRITICAL: Final = 2
WARNING_EMERGENCY: Final = 3
INITIALIZE_US: Final = 2_000_000  # battery.cpp: _battery_initialized 2 s after connecting


@dataclass(frozen=True, slots=True)
class BatterySettings:
    enabled: bool  # SIM_BAT_ENABLE
    min_fraction: float  # SIM_BAT_MIN_PCT / 100
    cells: int  # BAT1_N_CELLS
    v_charged: float  # BAT1_V_CHARGED
    v_empty: float  # BAT1_V_EMPTY
    low_thr: float  # BAT_LOW_THR
    crit_thr: float  # BAT_CRIT_THR
    emergen_thr: float  # BAT_EMERGEN_THR
    drain_us: float  # the discharge time in us: SIM_BAT_DRAIN, at least 1 s

    @classmethod
    def from_params(cls, p: ParamRegistry) -> BatterySettings:
        g = p.get
        return cls(bool(p["SIM_BAT_ENABLE"]), g("SIM_BAT_MIN_PCT") / 100.0,
                   int(p["BAT1_N_CELLS"]), g("BAT1_V_CHARGED"), g("BAT1_V_EMPTY"), g("BAT_LOW_THR"),
                   g("BAT_CRIT_THR"), g("BAT_EMERGEN_THR"), max(g("SIM_BAT_DRAIN"), 1.0) * 1e6)


def determine_warning(soc: float, s: BatterySettings) -> int:
    if soc < s.emergen_thr:
        return WARNING_EMERGENCY
    if soc < s.crit_thr:
        return WARNING_CRITICAL
    if soc < s.low_thr:
        return WARNING_LOW
    return WARNING_NONE


class BatterySimulator:
    """The charge, voltage, remaining fraction and warning, updated every tick."""

    def __init__(self) -> None:
        self.fraction = 1.0
        self._last_us = -1  # the last update while armed (-1: none since arming; an int, not None: see update)
        self.voltage_v = 16.2
        self.remaining = 1.0
        self.warning = WARNING_NONE
        self.failed = False  # failure battery off

    def update(self, now_us: int, armed: bool, s: BatterySettings) -> None:
        if armed:  # compiled, an `int | None` attribute would box now_us into a new Python int every tick
            if self._last_us >= 0:
                self.fraction -= (now_us - self._last_us) / s.drain_us
            self._last_us = now_us
        else:
            self.fraction, self._last_us = 1.0, -1
        self.fraction = max(self.fraction, s.min_fraction)
        self.voltage_v = ((1.0 - self.fraction) * s.v_empty + self.fraction * s.v_charged) * s.cells
        self.remaining = 0.0 if self.failed else self.fraction
        warning = WARNING_EMERGENCY if self.failed else determine_warning(self.fraction, s)
        if now_us < INITIALIZE_US or not s.enabled:
            warning = WARNING_NONE
        self.warning = max(self.warning, warning) if armed else warning  # while armed it only rises


# COM_LOW_BAT_ACT -> (action at critical, action at emergency); None: a warning only
_ACTIONS: Final[dict[int, tuple[NavState | None, NavState | None]]] = {
    1: (NavState.AUTO_RTL, NavState.AUTO_RTL),
    2: (NavState.AUTO_LAND, NavState.AUTO_LAND),
    3: (NavState.AUTO_RTL, NavState.AUTO_LAND),
    4: (NavState.AUTO_RTL, NavState.TERMINATION),
}


def battery_action(warning: int, low_bat_act: int, warning_at_arming: int) -> NavState | None:
    """The mode the battery failsafe wants for this warning (None: at most a warning)."""
    if warning <= warning_at_arming or warning < WARNING_CRITICAL:
        return None
    at_critical, at_emergency = _ACTIONS.get(low_bat_act, (None, None))
    return at_critical if warning == WARNING_CRITICAL else at_emergency


# what the user is told when the warning rises (batteryCheck.cpp's legacy mavlink_log, and failsafe framework.cpp's
# event for a warning-only action)
HEALTH_TEXTS: Final = {WARNING_LOW: "Low battery", WARNING_CRITICAL: "Critical battery",
                       WARNING_EMERGENCY: "Emergency battery level"}
WARN_EVENTS: Final = {WARNING_LOW: "Low battery level, return advised",
                      WARNING_CRITICAL: "Critical battery level, land now",
                      WARNING_EMERGENCY: "Emergency battery level, land immediately"}
