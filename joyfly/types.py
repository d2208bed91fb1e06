"""joyfly's contracts between the joystick side (sticks/: the sources, profiles/, mapping.py) and the flight side
(sticks/setpoints.py, link/, session/). No I/O here.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum
from typing import Protocol


@dataclass(frozen=True, slots=True)
class JoyState:
    """The whole raw state of a joystick, as the Linux js API reports it (axes -32767..32767, buttons 0/1).

    `time_s` is the source's clock (monotonic seconds, or the simulated clock when injected).
    `connected` False means the device vanished or the virtual source ended.
    """

    time_s: float
    axes: tuple[int, ...]
    buttons: tuple[int, ...]
    connected: bool = True


class JoystickSource(Protocol):
    """A real device, a FIFO/file of js_event records, a script or a replay. Never blocks longer than asked."""

    name: str
    path: str

    def poll(self, timeout_s: float) -> JoyState:
        """Read what has arrived (waiting at most timeout_s) and return the current state."""
        ...

    def close(self) -> None: ...


class Action(Enum):
    """Button actions a profile can bind."""

    ARM = "arm"  # hold 1 s: arm when disarmed, disarm when armed and landed
    TAKEOFF = "takeoff"
    LAND = "land"
    RETURN = "return"
    HOLD = "hold"
    OFFBOARD = "offboard"  # (re)enter OFFBOARD
    DEADMAN = "deadman"  # when configured: released -> hold position


@dataclass(frozen=True, slots=True)
class StickCommand:
    """Normalised stick demand, in the flying convention, whatever the controller's raw signs.

    forward: +1 = fly north (stick pushed forward)   right: +1 = fly east
    up: +1 = climb (centred throttle stick) or None when the profile has no throttle axis
    yaw: +1 = turn clockwise (yaw right)
    throttle_abs: 0..1 for a non-centring throttle (RC radios), else None
    pressed: actions whose button is down now; held_s: how long each has been held
    deadman_ok: None when no deadman is configured, else whether it is held
    """

    forward: float = 0.0
    right: float = 0.0
    up: float | None = None
    yaw: float = 0.0
    throttle_abs: float | None = None
    pressed: frozenset[Action] = frozenset()
    held_s: tuple[tuple[Action, float], ...] = ()
    deadman_ok: bool | None = None
    connected: bool = True
    time_s: float = 0.0


class Clock(Protocol):
    """Injected time: the wall clock in production, a simulated clock in tests."""

    def now(self) -> float: ...

    def sleep(self, seconds: float) -> None: ...
