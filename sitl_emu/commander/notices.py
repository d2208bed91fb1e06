"""What the commander sends as events beside its texts: the failsafe notices and the health and arming check report.

The commander hands each PX4 event (events/definition.py Px4Event) to the `SendEvent` callback it was given (the
vehicle's event stream, which the MAVLink events protocol serves); texts keep going through `emit`.
"""

from __future__ import annotations

from collections.abc import Callable

from sitl_emu.commander.failsafe import Decision
from sitl_emu.events.definition import Px4Event, px4_event
from sitl_emu.events.failsafe_notices import failsafe_notice
from sitl_emu.px4 import NavState, custom_mode

SendEvent = Callable[[Px4Event], None]


def drop(event: Px4Event) -> None:
    """A SendEvent for a commander nobody listens to (unit tests)."""


def failsafe_notice_event(user_intended: NavState, d: Decision, now_us: int) -> Px4Event:
    """framework.cpp notifyUser's event for an activated Decision: the user's intended mode as PX4's custom mode,
    the action (or the one its Hold delays), the delay, the cause."""
    definition, values = failsafe_notice(custom_mode(user_intended), d.action, d.delayed_action, d.cause, d.delay_s)
    return px4_event(definition, values, now_us)
