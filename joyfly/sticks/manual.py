"""Stick commands -> MANUAL_CONTROL (#69) values, as QGroundControl's joystick sends them to PX4. Pure, no I/O.

How PX4 reads the message (src/modules/mavlink/mavlink_receiver.cpp, handle_message_manual_control): x is the pitch
stick (forward), y the roll stick (right), r the yaw stick, each -1000..1000 with 1000 a full deflection; z is the
throttle, 0..1000 read as z / 500 - 1, so 500 is the centred stick; a field outside its range counts as 0 (for z:
centred). joyfly's mapping of the profile's shaped sticks (joyfly/sticks/mapping.py, mode 2):

- x = 1000 x forward, y = 1000 x right, r = 1000 x yaw;
- z = 500 + 500 x up for a centring throttle stick (centred: hold the altitude in POSCTL/ALTCTL, full up: climb at
  MPC_Z_VEL_MAX_UP, full down: descend at MPC_Z_VEL_MAX_DN); z = 1000 x throttle_abs for a radio's non-centring
  throttle (0 at the bottom); z = 500 when the profile has no throttle axis (nothing can take off then).

PX4 applies its own deadzone (MAN_DEADZONE) and expo on top of these values, as it does to QGC's.

The throttle interlock (`interlock`): PX4 arms in POSCTL/ALTCTL only with the throttle at or below 0.2 (z <= 600,
Commander::arm), and a throttle above the centre at arming would take off at once. joyfly sends centred sticks
(z = 500, the throttle QGC sends with its "centred throttle" option) until the vehicle is armed; it closes the
interlock when it sends the ARM (or takes control of a flying vehicle), and from then on the throttle it sends stays
at the centre until the stick has been at or below the centre once: a throttle held up during arming never launches
the vehicle, and one pushed once the vehicle is armed flies at once.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from joyfly.types import StickCommand

STICK_FULL = 1000
Z_CENTRE = 500
Z_FULL = 1000


@dataclass(frozen=True, slots=True)
class ManualInput:
    """One MANUAL_CONTROL's sticks: x forward, y right, r yaw in -1000..1000; z throttle 0..1000 (500 centred)."""

    x: int = 0
    y: int = 0
    z: int = Z_CENTRE
    r: int = 0

    @property
    def throttle(self) -> float:
        """The throttle as PX4 reads it: -1 (low) .. 1 (high), 0 centred."""
        return self.z / Z_CENTRE - 1.0

    def describe(self) -> str:
        return f"x {self.x:+5d} y {self.y:+5d} z {self.z:4d} r {self.r:+5d}"


CENTRED = ManualInput()


def _per_mille(value: float) -> int:
    return max(-STICK_FULL, min(STICK_FULL, round(value * STICK_FULL)))


def throttle_z(cmd: StickCommand) -> int:
    """MANUAL_CONTROL z for the throttle: the centring stick about 500, a radio's throttle from 0, else 500."""
    if cmd.up is not None:
        return max(0, min(Z_FULL, round(Z_CENTRE + Z_CENTRE * cmd.up)))
    if cmd.throttle_abs is not None:
        return max(0, min(Z_FULL, round(Z_FULL * cmd.throttle_abs)))
    return Z_CENTRE


def to_manual(cmd: StickCommand) -> ManualInput:
    """The stick command as MANUAL_CONTROL values (see the module docstring)."""
    return ManualInput(x=_per_mille(cmd.forward), y=_per_mille(cmd.right), z=throttle_z(cmd), r=_per_mille(cmd.yaw))


def from_throttle(throttle: float) -> int:
    """z for a throttle in PX4's -1..1 (the inverse of ManualInput.throttle)."""
    return max(0, min(Z_FULL, round(Z_CENTRE * (throttle + 1.0))))


def interlock(inp: ManualInput, latched: bool) -> tuple[ManualInput, bool]:
    """The throttle interlock: while latched, z stays at the centre; the latch opens once the stick is at or below
    the centre. Returns what to send and whether the latch is still closed."""
    if not latched:
        return inp, False
    if inp.z <= Z_CENTRE:
        return inp, False
    return replace(inp, z=Z_CENTRE), True
