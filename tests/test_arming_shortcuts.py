"""The allocation-free arming/mode checks the commander uses every cycle give the full checks' answers."""

from __future__ import annotations

import itertools

import pytest

from sitl_emu.flight import arming
from sitl_emu.px4 import NavState

FLAGS = list(itertools.product((False, True), repeat=3))


@pytest.mark.parametrize("nav_state", list(NavState))
def test_can_run_now_agrees_with_can_run_for_every_mode_and_input(nav_state):
    for ready, home, offboard in FLAGS:
        full = arming.can_run(nav_state, arming.CheckInputs(ready, home, offboard))
        assert arming.can_run_now(nav_state, ready, home, offboard) == full


@pytest.mark.parametrize("nav_state", list(NavState))
def test_can_arm_now_agrees_with_can_arm_for_every_mode_and_input(nav_state):
    for (ready, home, offboard), armed in itertools.product(FLAGS, (False, True)):
        full = arming.can_arm(nav_state, arming.CheckInputs(ready, home, offboard), armed)
        assert arming.can_arm_now(nav_state, ready, home, offboard, armed) == full
        assert arming.can_arm_now(nav_state, ready, home, offboard, armed) == full  # memoised answer too


def test_offboard_needs_a_fresh_signal_and_return_needs_home():
    assert not arming.can_run_now(NavState.OFFBOARD, True, True, False)
    assert arming.can_run_now(NavState.OFFBOARD, True, False, True)
    assert not arming.can_run_now(NavState.AUTO_RTL, True, False, False)
    assert not arming.can_arm_now(NavState.AUTO_LAND, True, True, False, False)  # Land prevents arming
