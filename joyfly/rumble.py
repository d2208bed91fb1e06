"""Rumble: a short pulse on the pad when something needs the pilot's attention, read from the session's views (no
change to the session): a push against the fence, a failsafe, the link lost, low battery. Only an SDL device with
rumble pulses (SDL_GameControllerRumble / SDL_JoystickRumble); on any other nothing happens, silently; `--no-rumble`
turns it off.

What counts (one pulse per occurrence):
  - fence push: in the air within FENCE_PUSH_M of a side of the fence with the stick pushing towards that side
    (again only after the stick has let go of it);
  - failsafe: a new STATUSTEXT from the vehicle with "failsafe" in it (PX4's "Failsafe activated: ...");
  - low battery: a new STATUSTEXT about a low, critical or emergency battery level (PX4's battery warnings);
  - link lost: the vehicle's heartbeat stops (the session's link watchdog).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

from joyfly.session.core import Level, Note, SessionView

FENCE_PUSH_M = 0.5  # closer to a fence side than this, pushing outwards, is a push
PUSH_STICK = 0.2  # stick deflection towards the side that counts as pushing
LANDED_STATE_ON_GROUND = 1  # MAV_LANDED_STATE_ON_GROUND


class Rumbler(Protocol):
    def rumble(self, low: float, high: float, duration_ms: int) -> bool: ...


@dataclass(frozen=True, slots=True)
class Pulse:
    low: float  # the low-frequency (left) motor, 0..1
    high: float  # the high-frequency (right) motor, 0..1
    duration_ms: int


PULSES = {
    "fence": Pulse(0.3, 0.7, 150),
    "failsafe": Pulse(1.0, 1.0, 500),
    "link": Pulse(0.8, 0.3, 400),
    "battery": Pulse(0.6, 0.6, 300),
}


def new_texts(before: tuple[str, ...], now: tuple[str, ...]) -> tuple[str, ...]:
    """The texts at the end of `now` that `before` (the previous last few) did not have yet."""
    for overlap in range(min(len(before), len(now)), 0, -1):
        if before[-overlap:] == now[:overlap]:
            return now[overlap:]
    return now


def text_events(texts: tuple[str, ...]) -> list[str]:
    out = []
    for text in texts:
        low = text.lower()
        if "failsafe" in low:
            out.append("failsafe")
        if "battery" in low and any(word in low for word in ("low", "critical", "emergency")):
            out.append("battery")
    return out


def pushing_fence(view: SessionView, yaw_rad: float | None) -> bool:
    """In the air, near a fence side, with the stick towards it (OFFBOARD sticks fly north/east; PX4's manual
    modes fly forward/right of the nose, so `yaw_rad` turns them)."""
    pos = view.pos_ned_m
    fence = view.fence
    if pos is None or not fence.enabled or not view.armed or view.landed_state == LANDED_STATE_ON_GROUND:
        return False
    north, east = view.stick.forward, view.stick.right
    if yaw_rad is not None:
        c, s = math.cos(yaw_rad), math.sin(yaw_rad)
        north, east = c * north - s * east, s * north + c * east
    for offset, push in ((pos[0] - fence.home_ned_m[0], north), (pos[1] - fence.home_ned_m[1], east)):
        if abs(offset) > fence.half_width_m - FENCE_PUSH_M and push * math.copysign(1.0, offset) > PUSH_STICK:
            return True
    return False


class Haptics:
    """Turns a stream of session views into rumble pulses."""

    def __init__(self, rumbler: Rumbler, yaw_of: Callable[[], float] | None = None) -> None:
        self.rumbler = rumbler
        self.yaw_of = yaw_of
        self.pulsed: list[str] = []
        self._texts: tuple[str, ...] = ()
        self._link_ok = False
        self._pushing = False

    def events(self, view: SessionView) -> list[str]:
        found = text_events(new_texts(self._texts, view.statustexts))
        self._texts = view.statustexts
        if self._link_ok and not view.link_ok and view.heard:
            found.append("link")
        self._link_ok = view.link_ok
        pushing = pushing_fence(view, self.yaw_of() if self.yaw_of is not None else None)
        if pushing and not self._pushing:
            found.append("fence")
        self._pushing = pushing
        return found

    def show(self, view: SessionView) -> None:
        for event in self.events(view):
            pulse = PULSES[event]
            self.rumbler.rumble(pulse.low, pulse.high, pulse.duration_ms)
            self.pulsed.append(event)


class HapticView:
    """A session view (the terminal's, the browser's) that also pulses the pad (`haptics`), and passes on what the
    device itself has to say (an SDL source's `news`: another controller plugged in and ignored) as warnings."""

    def __init__(self, inner: Any, haptics: Haptics | None, device: Any = None) -> None:
        self.inner = inner
        self.haptics = haptics
        self.device = device

    def note(self, note: Note) -> None:
        self.inner.note(note)

    def show(self, view: SessionView) -> None:
        news = getattr(self.device, "news", None)
        while news:
            self.inner.note(Note(view.time_s, Level.WARN, news.pop(0)))
        self.inner.show(view)
        if self.haptics is not None:
            self.haptics.show(view)

    def close(self, keep: bool = True) -> None:
        self.inner.close(keep=keep)


def device_of(sticks: Any) -> Any:
    """The device behind a stick source (through the mapping's and --record's wrappers)."""
    source = getattr(sticks, "source", sticks)
    return getattr(source, "source", source)


def rumbler_of(sticks: Any) -> Rumbler | None:
    """The rumbling device behind a stick source, or None when it has no rumble."""
    source = device_of(sticks)
    return source if getattr(source, "has_rumble", False) else None
