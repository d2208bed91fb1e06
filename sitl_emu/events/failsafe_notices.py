"""The failsafe notices PX4's commander sends as events (src/modules/commander/failsafe/framework.cpp notifyUser).

When the failsafe action in force gets worse, notifyUser sends one event beside its STATUSTEXT ("Failsafe activated"
or "Failsafe activated: entering Hold for N seconds", which the commander says as before). Its first argument is the
user's intended mode as PX4's custom mode (the 32-bit px4_custom_mode data), then the action (failsafe_action_t),
the delay in whole seconds (the Hold before a delayed action) and the cause (failsafe_cause_t) as the case needs:
- a Hold before a delayed action: commander_failsafe_enter_generic_hold (no cause) or commander_failsafe_enter_hold;
- an action at once: commander_failsafe_enter_generic (no cause) or commander_failsafe_enter; without a cause, an
  action that takes position control away (Descend, the Altitude or Stabilized fallback) is
  commander_failsafe_enter_autopilot_disengaged ("Autopilot disengaged" only there since PX4 #23543);
- a warning (Action::Warn, no mode change: GF_ACTION 1): commander_failsafe_enter_generic_warn (no cause) or
  commander_failsafe_enter_warn, at Warning level and with no STATUSTEXT (PX4 #24858 keeps "Failsafe activated" for
  the actions that do something).
The battery's warnings are not decided by the emulator's Failsafe: they are the texts catalogue.py matches
(commander_failsafe_enter_low_bat and the two others).
"""

from __future__ import annotations

from typing import Final

from sitl_emu.events import enums
from sitl_emu.events.definition import EventDefinition, Values
from sitl_emu.events.library import Log

_ACTION = enums.qualified(enums.FAILSAFE_ACTION)
_CAUSE = enums.qualified(enums.FAILSAFE_CAUSE)

ACTION_NONE: Final = 0
ACTION_WARN: Final = 1
ACTION_HOLD: Final = 5
# failsafe_action_t values after which no controller holds the position: fallback_altctrl, fallback_stabilized, descend
_DISENGAGING: Final = frozenset({3, 4, 8})
# failsafe_cause_t (framework.h Cause); the battery's: battery_status's warning level + CAUSE_BATTERY_OFFSET
CAUSE_GENERIC: Final = 0
CAUSE_MANUAL_CONTROL_LOSS: Final = 1
CAUSE_GCS_CONNECTION_LOSS: Final = 2
CAUSE_BATTERY_OFFSET: Final = 2


def _notice(name: str, message: str, arguments: tuple[str, ...]) -> EventDefinition:
    """{events::Log::Critical, events::LogInternal::Warning}, as every failsafe activation."""
    return EventDefinition(name, message, arguments, Log.CRITICAL, Log.WARNING)


ENTER_GENERIC_HOLD = _notice("commander_failsafe_enter_generic_hold",
                             "Failsafe activated: switching to {2} in {3} seconds", ("uint32_t", _ACTION, "uint16_t"))
ENTER_HOLD = _notice("commander_failsafe_enter_hold", "{4}: switching to {2} in {3} seconds",
                     ("uint32_t", _ACTION, "uint16_t", _CAUSE))
ENTER_GENERIC = _notice("commander_failsafe_enter_generic", "Failsafe activated: switching to {2}",
                        ("uint32_t", _ACTION))
ENTER_AUTOPILOT_DISENGAGED = _notice("commander_failsafe_enter_autopilot_disengaged",
                                     "Failsafe activated: Autopilot disengaged, switching to {2}",
                                     ("uint32_t", _ACTION))
ENTER = _notice("commander_failsafe_enter", "{3}: switching to {2}", ("uint32_t", _ACTION, _CAUSE))

ENTER_GENERIC_WARN = EventDefinition("commander_failsafe_enter_generic_warn", "Failsafe warning:", ("uint32_t",),
                                     Log.WARNING, Log.WARNING)
ENTER_WARN = EventDefinition("commander_failsafe_enter_warn", "Failsafe warning: {2}", ("uint32_t", _CAUSE),
                             Log.WARNING, Log.WARNING)

DEFINITIONS: Final = (ENTER_GENERIC_HOLD, ENTER_HOLD, ENTER_GENERIC, ENTER_AUTOPILOT_DISENGAGED, ENTER,
                      ENTER_GENERIC_WARN, ENTER_WARN)


def failsafe_notice(mavlink_mode: int, action: int, delayed_action: int, cause: int,
                    delay_s: int) -> tuple[EventDefinition, Values]:
    """notifyUser's event for the action now in force (`delayed_action`: what follows the Hold, or none)."""
    if action == ACTION_HOLD and delayed_action != ACTION_NONE:
        if cause == CAUSE_GENERIC:
            return ENTER_GENERIC_HOLD, (mavlink_mode, delayed_action, delay_s)
        return ENTER_HOLD, (mavlink_mode, delayed_action, delay_s, cause)
    if action == ACTION_WARN:
        if cause == CAUSE_GENERIC:
            return ENTER_GENERIC_WARN, (mavlink_mode,)
        return ENTER_WARN, (mavlink_mode, cause)
    if cause == CAUSE_GENERIC:
        return (ENTER_AUTOPILOT_DISENGAGED if action in _DISENGAGING else ENTER_GENERIC), (mavlink_mode, action)
    return ENTER, (mavlink_mode, action, cause)
