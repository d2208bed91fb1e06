from __future__ import annotations

import json
import math

import pytest
from support import REPO_ROOT

from sitl_emu.params import (
    ParamDef,
    ParamError,
    ParamRegistry,
    ParamType,
    all_definitions,
    default_registry,
    integer,
    real,
)
from sitl_emu.params.catalog import EMULATOR_DEFAULTS, VOLATILE, px4_catalog
from sitl_emu.params.registry import same_value

# The recorded PX4 list (../shared/reference, beside the repository or beside the main checkout of a worktree)
REFERENCES = [up / "shared" / "reference" / "px4-params.json" for up in (REPO_ROOT.parent, REPO_ROOT.parent.parent)]


def px4_list() -> dict[str, dict]:
    """name -> {type, value, index} as PX4 SITL sent them; the packaged catalog when the reference is not here."""
    found = next((path for path in REFERENCES if path.exists()), None)
    if found is not None:
        return json.loads(found.read_text())["params"]
    cat = px4_catalog()
    return {name: {"type": cat.defs[i].type.value, "value": cat.px4_defaults[name], "index": i}
            for i, name in enumerate(cat.used)}


@pytest.fixture
def reg():
    return default_registry()


def test_defaults_are_px4s(reg):
    assert reg.get("MPC_XY_VEL_MAX") == 12.0
    assert reg.get("MC_ROLLRATE_P") == 0.15
    assert reg.get("SIH_T_MAX") == 5.0
    assert reg.get("SIH_LOC_H0") == 489.4
    assert reg.get("MPC_USE_HTE") == 1 and isinstance(reg.get("MPC_USE_HTE"), int)
    assert reg.definition("MPC_THR_HOVER").type is ParamType.REAL32


def test_set_keeps_the_value_and_bumps_the_version(reg):
    v0 = reg.version
    assert reg.set("MPC_XY_VEL_MAX", 8) == 8.0
    assert reg.get("MPC_XY_VEL_MAX") == 8.0
    assert reg.version == v0 + 1
    reg.set("MPC_XY_VEL_MAX", 8)  # unchanged value: no new version
    assert reg.version == v0 + 1


def test_a_reader_that_keeps_the_change_count_sees_every_change(reg):
    """The tick path's settings caches keep `changes` (params/changes.py), not the registry: it is the version."""
    changes = reg.changes
    reg.set("MPC_XY_VEL_MAX", 8)
    assert changes.value == reg.version == 1
    reg.reset()
    assert changes.value == reg.version == 2


def test_a_watch_says_changed_once_after_any_number_of_changes(reg):
    """Settings built from the parameters are rebuilt when `watch.changed()` says so (params/changes.py)."""
    built_now, built_at_first_use = reg.changes.watch(), reg.changes.watch(current=False)
    assert not built_now.changed()
    assert built_at_first_use.changed() and not built_at_first_use.changed()
    reg.set("MPC_XY_VEL_MAX", 8)
    reg.set("MPC_XY_VEL_MAX", 9)
    assert built_now.changed() and not built_now.changed()
    assert built_at_first_use.changed() and not built_at_first_use.changed()
    reg.set("MPC_XY_VEL_MAX", 9)  # the same value: no change, nothing to rebuild
    assert not built_now.changed()


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
    for d in reg.known():
        assert d.min <= d.default <= d.max, d.name


def test_the_list_is_px4s_names_types_defaults_and_order(reg):
    px4 = px4_list()
    assert len(reg) == len(px4) == 994
    assert [reg.name_at(i) for i in range(len(reg))] == sorted(px4, key=lambda n: px4[n]["index"])
    for d in reg:
        assert d.type.value == px4[d.name]["type"], d.name
        assert reg.index_of(d.name) == px4[d.name]["index"], d.name
        if d.name not in EMULATOR_DEFAULTS:
            assert same_value(d.type, reg.get(d.name), px4[d.name]["value"]), d.name


def test_the_emulators_definitions_agree_with_px4_but_where_listed_and_why(reg):
    px4 = px4_list()
    differing = {d.name for d in all_definitions()
                 if d.name in px4 and not same_value(d.type, d.default, px4[d.name]["value"])}
    assert differing == set(EMULATOR_DEFAULTS)
    assert reg.get("SIH_LOC_H0") == pytest.approx(px4["SIH_LOC_H0"]["value"]) == pytest.approx(489.4)
    assert all(d.type.value == px4[d.name]["type"] for d in all_definitions() if d.name in px4)
    assert reg.definition("MPC_XY_VEL_MAX").unit == "m/s" and reg.definition("MPC_XY_VEL_MAX").doc


def test_definitions_px4_does_not_list_are_known_by_name_but_not_used(reg):
    hidden = {d.name for d in reg.known()} - {d.name for d in reg}
    assert {"MIS_DIST_1WP", "MIS_TKO_LAND_REQ", "MPC_USE_HTE", "LNDMC_TRIG_TIME"} <= hidden
    assert "MIS_DIST_1WP" in reg and reg.index_of("MIS_DIST_1WP") == -1
    assert reg.get("MIS_DIST_1WP") == 10000.0 and reg.definition("MIS_TKO_LAND_REQ").type is ParamType.INT32


def test_mark_used_lists_in_name_order_and_refuses_unknown_names(reg):
    before = [reg.name_at(i) for i in range(len(reg))]
    reg.mark_used("MIS_TKO_LAND_REQ")
    reg.mark_used("MIS_TKO_LAND_REQ")  # twice: once
    after = [reg.name_at(i) for i in range(len(reg))]
    assert after == sorted([*before, "MIS_TKO_LAND_REQ"])
    assert reg.index_of("MIS_TKO_LAND_REQ") == after.index("MIS_TKO_LAND_REQ")
    with pytest.raises(ParamError):
        reg.mark_used("NO_SUCH_PARAM")


def test_a_parameter_only_px4_defines_is_checked_by_type_where_px4_states_no_range(reg):
    assert reg.set("ADSB_CALLSIGN_1", 2**31 - 1) == 2**31 - 1
    for value, words in ((2**31, "within"), (1.5, "integer"), (math.nan, "finite")):
        with pytest.raises(ParamError, match=words):
            reg.set("ADSB_CALLSIGN_1", value)
    assert reg.set("CAL_ACC0_XOFF", -3.0e38) == -3.0e38
    with pytest.raises(ParamError, match="finite"):
        reg.set("CAL_ACC0_XOFF", 1e39)  # beyond float32: PX4 would store infinity


def test_a_real_set_to_the_same_float32_changes_nothing(reg):
    v0 = reg.version
    reg.set("MPC_XY_P", 0.949999988079071)  # 0.95 as float32, as a client sends it back
    assert reg.get("MPC_XY_P") == 0.95 and reg.version == v0


def test_changed_and_reset(reg):
    reg.set("MPC_XY_P", 1.2)
    reg.set("BAT1_N_CELLS", 6)
    assert reg.changed() == {"BAT1_N_CELLS": 6, "MPC_XY_P": 1.2} and not reg.is_default("MPC_XY_P")
    reg.reset(["MPC_XY_P"])
    assert reg.changed() == {"BAT1_N_CELLS": 6}
    v = reg.version
    reg.reset()
    assert reg.changed() == {} and reg.version == v + 1
    reg.reset()
    assert reg.version == v + 1  # nothing to reset: no new version


def test_the_hash_leaves_out_volatile_parameters():
    plain = ParamRegistry([real("B_REAL", 2.5), integer("A_INT", 7)])
    with_volatile = ParamRegistry([real("B_REAL", 2.5), integer("A_INT", 7),
                                   ParamDef("C_UUID", ParamType.INT32, 3, volatile=True)])
    assert with_volatile.hash_check() == plain.hash_check()
    assert {d.name for d in default_registry()} >= VOLATILE
    assert all(default_registry().definition(n).volatile for n in VOLATILE)


def test_the_hash_follows_every_value_and_the_used_set(reg):
    seen = {reg.hash_check()}
    reg.set("MPC_XY_P", 1.0)
    seen.add(reg.hash_check())
    reg.set("BAT1_N_CELLS", 5)
    seen.add(reg.hash_check())
    reg.mark_used("MIS_DIST_1WP")
    seen.add(reg.hash_check())
    assert len(seen) == 4
