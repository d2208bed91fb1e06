from __future__ import annotations

import math

import pytest

from sitl_emu.params import ParamError, ParamType, default_registry


@pytest.fixture
def reg():
    return default_registry()


def test_defaults_are_px4s(reg):
    assert reg.get("MPC_XY_VEL_MAX") == 12.0
    assert reg.get("MC_ROLLRATE_P") == 0.15
    assert reg.get("SIH_T_MAX") == 5.0
    assert reg.get("SIH_LOC_H0") == 488.0
    assert reg.get("MPC_USE_HTE") == 1 and isinstance(reg.get("MPC_USE_HTE"), int)
    assert reg.definition("MPC_THR_HOVER").type is ParamType.REAL32


def test_set_keeps_the_value_and_bumps_the_version(reg):
    v0 = reg.version
    assert reg.set("MPC_XY_VEL_MAX", 8) == 8.0
    assert reg.get("MPC_XY_VEL_MAX") == 8.0
    assert reg.version == v0 + 1
    reg.set("MPC_XY_VEL_MAX", 8)  # unchanged value: no new version
    assert reg.version == v0 + 1


@pytest.mark.parametrize(("name", "value", "words"), [
    ("MPC_XY_VEL_MAX", math.nan, "finite"),
    ("MPC_XY_VEL_MAX", math.inf, "finite"),
    ("MPC_XY_VEL_MAX", 25.0, "within"),
    ("MPC_TILTMAX_AIR", 5.0, "within"),
    ("MPC_USE_HTE", 0.5, "integer"),
    ("MPC_NOT_A_PARAM", 1.0, "Unknown"),
])
def test_bad_values_are_refused_with_one_clear_sentence(reg, name, value, words):
    before = reg.values()
    v0 = reg.version
    with pytest.raises(ParamError) as err:
        reg.set(name, value)
    msg = str(err.value)
    assert words in msg and msg.endswith(".") and "\n" not in msg
    assert reg.values() == before and reg.version == v0


def test_names_are_in_order_and_indexable(reg):
    names = [reg.name_at(i) for i in range(len(reg))]
    assert names == sorted(names)
    assert reg.index_of(names[3]) == 3
    assert all(len(n) <= 16 for n in names)
    with pytest.raises(ParamError):
        reg.name_at(len(reg))


def test_every_default_lies_within_its_range(reg):
    for d in reg:
        assert d.min <= d.default <= d.max, d.name
