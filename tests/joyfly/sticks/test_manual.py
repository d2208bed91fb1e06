"""Sticks -> MANUAL_CONTROL values (joyfly/sticks/manual.py): the mapping, the throttle interlock, PX4's shaping."""

from __future__ import annotations

import pytest

from joyfly.sticks.manual import CENTRED, ManualInput, from_throttle, interlock, throttle_z, to_manual
from joyfly.sticks.manual_fence import px4_shape, px4_unshape
from joyfly.types import StickCommand


@pytest.mark.parametrize(("cmd", "expected"), [
    (StickCommand(), ManualInput(0, 0, 500, 0)),  # no throttle axis: centred
    (StickCommand(up=0.0), ManualInput(0, 0, 500, 0)),
    (StickCommand(forward=1.0, right=-1.0, up=1.0, yaw=0.5), ManualInput(1000, -1000, 1000, 500)),
    (StickCommand(forward=-0.25, right=0.333, up=-1.0, yaw=-1.0), ManualInput(-250, 333, 0, -1000)),
    (StickCommand(up=0.5), ManualInput(0, 0, 750, 0)),
    (StickCommand(throttle_abs=0.0), ManualInput(0, 0, 0, 0)),  # a radio's throttle at the bottom
    (StickCommand(throttle_abs=0.62), ManualInput(0, 0, 620, 0)),
])
def test_mode_2_sticks_become_manual_control_values(cmd: StickCommand, expected: ManualInput) -> None:
    assert to_manual(cmd) == expected


def test_values_never_leave_the_ranges_px4_accepts() -> None:
    wild = StickCommand(forward=3.0, right=-7.0, up=2.0, yaw=-1.5)
    inp = to_manual(wild)
    assert (inp.x, inp.y, inp.z, inp.r) == (1000, -1000, 1000, -1000)
    assert throttle_z(StickCommand(up=-4.0)) == 0 and throttle_z(StickCommand(throttle_abs=1.7)) == 1000


def test_throttle_as_px4_reads_it_and_back() -> None:
    assert ManualInput(z=500).throttle == 0.0 and ManualInput(z=0).throttle == -1.0
    assert ManualInput(z=1000).throttle == 1.0 and ManualInput(z=600).throttle == pytest.approx(0.2)
    for z in (0, 137, 500, 650, 1000):
        assert from_throttle(ManualInput(z=z).throttle) == z


def test_centred_is_a_safe_arming_throttle_for_posctl() -> None:
    assert CENTRED.throttle <= 0.2  # Commander::arm: climb-rate modes need throttle <= 0.2 (z <= 600)
    assert CENTRED.z >= 100  # and it is no arm/disarm stick gesture (z < 100 with full yaw)


def test_interlock_keeps_the_throttle_centred_until_the_stick_comes_down() -> None:
    up = ManualInput(x=300, z=900, r=-200)
    sent, latched = interlock(up, True)
    assert sent == ManualInput(x=300, z=500, r=-200) and latched  # the other sticks pass
    sent, latched = interlock(ManualInput(z=520), latched)
    assert sent.z == 500 and latched
    sent, latched = interlock(ManualInput(z=500), latched)
    assert sent.z == 500 and not latched  # at the centre: open
    sent, latched = interlock(up, latched)
    assert sent == up and not latched  # stays open
    assert interlock(ManualInput(z=0), True) == (ManualInput(z=0), False)  # below the centre opens it too


@pytest.mark.parametrize(("stick", "shaped"), [(0.0, 0.0), (0.1, 0.0), (-0.05, 0.0), (1.0, 1.0), (-1.0, -1.0),
                                                (0.5, 0.2305), (-0.5, -0.2305)])
def test_px4_shaping_matches_its_sticks_library(stick: float, shaped: float) -> None:
    assert px4_shape(stick) == pytest.approx(shaped, abs=1e-4)  # spec 3.1: throttle 0.5 -> 0.2305


@pytest.mark.parametrize("e", [0.001, 0.05, 0.2305, 0.5, 0.9, 1.0, -0.3, -1.0])
def test_unshape_inverts_px4_shaping(e: float) -> None:
    stick = px4_unshape(e)
    assert abs(stick) <= 1.0 and px4_shape(stick) == pytest.approx(e, abs=1e-6)
    assert px4_unshape(0.0) == 0.0
