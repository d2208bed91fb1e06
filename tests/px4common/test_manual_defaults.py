"""The manual modes' defaults both programs use are PX4's: each equals the default in PX4's parameter list
(sitl_emu/params/px4_params.csv, read through the emulator's registry)."""

from __future__ import annotations

import pytest

from px4common import manual_defaults
from sitl_emu.params import default_registry

NAMES = [n for n in vars(manual_defaults) if n.isupper() and n != "STICK_EXPO"]


@pytest.mark.parametrize("name", NAMES)
def test_each_default_is_px4s_own(name: str) -> None:
    assert default_registry().get(name) == pytest.approx(getattr(manual_defaults, name), rel=1e-6)


def test_the_expo_is_the_old_expo_parameters_default() -> None:
    assert manual_defaults.STICK_EXPO == 0.6
