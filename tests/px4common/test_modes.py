"""px4common's PX4 numbering: custom_mode's layout, its names, MAV_RESULT; the one table both programs read."""

from __future__ import annotations

import pytest
from pymavlink.dialects.v20 import common as mavlink2

from px4common.modes import (
    AutoSubMode,
    MainMode,
    custom_mode_name,
    decode_custom_mode,
    encode_custom_mode,
    main_mode,
)
from px4common.results import MavResult, result_name


@pytest.mark.parametrize(("custom_mode", "name"), [
    (6 << 16, "OFFBOARD"),
    (50593792, "AUTO.LOITER"),  # PX4 SITL's HEARTBEAT in Hold
    (84148224, "AUTO.RTL"),
    (100925440, "AUTO.LAND"),
    (3 << 16, "POSCTL"),
    ((1 << 24) | (3 << 16), "POSCTL"),  # Orbit is a POSCTL sub mode
    (99 << 16, f"CMODE({99 << 16})"),
    ((7 << 24) | (4 << 16), f"CMODE({(7 << 24) | (4 << 16)})"),  # AUTO with a sub mode PX4 does not define
])
def test_custom_mode_names_are_mavros_names_or_cmode(custom_mode: int, name: str) -> None:
    assert custom_mode_name(custom_mode) == name


def test_custom_mode_layout_is_sub_then_main_in_the_high_bytes() -> None:
    value = encode_custom_mode(MainMode.AUTO, AutoSubMode.LOITER)
    assert value == 50593792
    assert decode_custom_mode(value) == (MainMode.AUTO, AutoSubMode.LOITER)
    assert main_mode(value) == MainMode.AUTO
    assert encode_custom_mode(MainMode.OFFBOARD) == 6 << 16


def test_a_result_is_named_as_mavlink_names_it_or_by_its_number() -> None:
    assert result_name(MavResult.DENIED) == "DENIED" == mavlink2.enums["MAV_RESULT"][2].name.removeprefix("MAV_RESULT_")
    assert result_name(99) == "99"  # tests/sitl_emu/test_px4.py checks every MavResult against common.xml
