"""The session for a `--control` choice: OFFBOARD setpoints (velocity, step) or PX4's manual modes with
MANUAL_CONTROL (position, altitude)."""

from __future__ import annotations

from collections.abc import Callable

from joyfly.link.vehicle_link import VehicleLink
from joyfly.session.core import Note, SessionSettings, StickSource
from joyfly.session.flight_session import FlightSession
from joyfly.session.loop import SessionLoop
from joyfly.session.manual_session import MANUAL_CONTROLS, ManualSession
from joyfly.types import Clock


def make_session(link: VehicleLink, sticks: StickSource, clock: Clock, settings: SessionSettings,
                 on_note: Callable[[Note], None] | None = None) -> SessionLoop:
    if settings.limits.control in MANUAL_CONTROLS:
        return ManualSession(link, sticks, clock, settings, on_note=on_note)
    return FlightSession(link, sticks, clock, settings, on_note=on_note)
