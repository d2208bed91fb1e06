"""Rumble pulses from the session's views: a fence push (once per push), a failsafe, low battery, the link lost;
nothing otherwise."""

from __future__ import annotations

from dataclasses import replace

from joyfly.rumble import PULSES, Haptics, new_texts, rumbler_of
from joyfly.session.core import FlightStats, Phase, SessionView
from joyfly.sticks.setpoints import Fence
from joyfly.types import StickCommand


class Pad:
    def __init__(self) -> None:
        self.calls: list[tuple[float, float, int]] = []
        self.has_rumble = True

    def rumble(self, low: float, high: float, duration_ms: int) -> bool:
        self.calls.append((low, high, duration_ms))
        return True


BASE = SessionView(time_s=0.0, phase=Phase.FLYING, link_ok=True, mode="OFFBOARD", armed=True, landed_state=2,
                   pos_ned_m=(0.0, 0.0, -3.0), setpoint=None, streaming=True, stick=StickCommand(), joystick_ok=True,
                   fence=Fence((0.0, 0.0, 0.0), 5.0), stats=FlightStats(), statustexts=(), notes=(),
                   link_description="udp")


def run(views: list[SessionView], yaw: float | None = None) -> list[str]:
    haptics = Haptics(Pad(), (lambda: yaw) if yaw is not None else None)
    for view in views:
        haptics.show(view)
    return haptics.pulsed


def test_pushing_against_the_fence_pulses_once_per_push() -> None:
    near = replace(BASE, pos_ned_m=(4.7, 0.0, -3.0))
    push = replace(near, stick=StickCommand(forward=0.8))
    assert run([BASE, near, push, push, push]) == ["fence"]
    assert run([near, push, near, push]) == ["fence", "fence"]  # let go, pushed again
    assert run([replace(BASE, stick=StickCommand(forward=1.0)), replace(near, stick=StickCommand(forward=-0.8))]) == []
    assert run([replace(push, landed_state=1)]) == []  # on the ground: no
    west = replace(BASE, pos_ned_m=(0.0, -4.8, -3.0), stick=StickCommand(right=-0.5))
    assert run([west]) == ["fence"]


def test_in_manual_modes_the_stick_turns_with_the_nose() -> None:
    east_wall = replace(BASE, pos_ned_m=(0.0, 4.8, -3.0), stick=StickCommand(forward=0.8))
    assert run([east_wall]) == []  # OFFBOARD: forward is north
    assert run([east_wall], yaw=1.5708) == ["fence"]  # nose east: forward is east


def test_failsafe_battery_and_link_loss_pulse() -> None:
    views = [BASE,
             replace(BASE, statustexts=("Takeoff detected",)),
             replace(BASE, statustexts=("Takeoff detected", "Failsafe activated: entering Hold for 5 seconds")),
             replace(BASE, statustexts=("Takeoff detected", "Failsafe activated: entering Hold for 5 seconds")),
             replace(BASE, statustexts=("Failsafe activated: entering Hold for 5 seconds", "Low battery level!")),
             replace(BASE, link_ok=False),
             replace(BASE, link_ok=False)]
    assert run(views) == ["failsafe", "battery", "link"]


def test_new_texts_sees_repeats_after_the_window_moves() -> None:
    assert new_texts(("a", "b"), ("a", "b", "c")) == ("c",)
    assert new_texts(("a", "b", "c", "d", "e"), ("b", "c", "d", "e", "e")) == ("e",)
    assert new_texts((), ("x",)) == ("x",)


def test_the_pulse_reaches_the_rumbler_and_only_a_rumbling_source_is_one() -> None:
    pad = Pad()
    haptics = Haptics(pad)
    haptics.show(replace(BASE, pos_ned_m=(4.7, 0.0, -3.0), stick=StickCommand(forward=0.8)))
    fence = PULSES["fence"]
    assert pad.calls == [(fence.low, fence.high, fence.duration_ms)]

    class Mapped:
        def __init__(self, source: object) -> None:
            self.source = source

    assert rumbler_of(Mapped(pad)) is pad
    quiet = Pad()
    quiet.has_rumble = False
    assert rumbler_of(Mapped(quiet)) is None and rumbler_of(Mapped(object())) is None
