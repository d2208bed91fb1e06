"""Parameter metadata (issue 13): PX4's range and unit and our one-line description of every listed parameter.

sitl_emu/params/px4_param_meta.csv is written by tools/px4_param_meta.py from PX4's parameter reference; the tests
check the packaged file on its own (order, defaults inside the ranges, units, descriptions, the registry using it,
the emulator's own definitions agreeing with it) and, where PX4's reference is on this machine, that the tool
reproduces the file and that no description repeats PX4's words.
"""

from __future__ import annotations

import importlib.util
import os
import sys
from pathlib import Path
from types import ModuleType

import pytest
from support import REPO_ROOT

from sitl_emu.params import all_definitions, default_registry
from sitl_emu.params.catalog import Meta, px4_catalog, px4_metadata
from sitl_emu.params.registry import ParamError, ParamType, float32, same_value

# Every unit PX4's metadata uses for the listed parameters, plus those our definitions add where PX4 states none.
# PX4 spells Celsius 'celcius'; the units are taken as PX4 writes them.
KNOWN_UNITS = frozenset({
    "", "%", "(m/s)^2", "(m/s^2)^2", "1/s", "1/s^2", "A", "A/%", "Hz", "MiB", "N", "N/(m/s)", "Nm", "Nm/(rad/s)",
    "Ohm", "SD", "V", "celcius", "deg", "deg/s", "deg/s^2", "g0", "gauss", "gauss/s", "hPa", "kg", "kg m^2",
    "kg/m^2", "m", "m/m", "m/s", "m/s^2", "m/s^2/sqrt(Hz)", "m/s^3", "m^2", "mAh", "min", "mm", "ms", "norm",
    "normalized_thrust", "normalized_thrust/s", "rad", "rad s/m", "rad/s", "rad/s^2", "s", "us",
})

# PX4's reference, if this machine has it: $PX4_PARAM_REFERENCE, or ../shared/reference/ beside the repository.
REFERENCES = [Path(os.environ["PX4_PARAM_REFERENCE"])] if os.environ.get("PX4_PARAM_REFERENCE") else []
REFERENCES += [up / "shared" / "reference" / "px4-parameter-reference.md" for up in (REPO_ROOT.parent,
                                                                                     REPO_ROOT.parent.parent)]


@pytest.fixture(scope="module")
def meta() -> dict[str, Meta]:
    return px4_metadata()


def _tool() -> ModuleType:
    spec = importlib.util.spec_from_file_location("px4_param_meta", REPO_ROOT / "tools" / "px4_param_meta.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up
    spec.loader.exec_module(module)
    return module


def test_the_file_describes_every_listed_parameter_in_px4s_order(meta):
    assert list(meta) == list(px4_catalog().used)
    assert len(meta) == 994


def test_how_much_px4_states(meta):
    """As of PX4 0d4ae424d3: 724 parameters with a stated bound (610 with both), 500 with a unit; all 994 described."""
    ranged = [n for n, m in meta.items() if m.min is not None or m.max is not None]
    assert len(ranged) >= 700 and sum(1 for m in meta.values() if m.unit) >= 480
    assert all(m.doc for m in meta.values())


def test_every_px4_default_lies_within_px4s_stated_range(meta):
    cat = px4_catalog()
    for name, m in meta.items():
        default = cat.px4_defaults[name]
        assert m.min is None or m.min <= default, name
        assert m.max is None or default <= m.max, name
        assert m.min is None or m.max is None or m.min <= m.max, name


def test_units_are_known_and_descriptions_are_one_short_line(meta):
    assert {m.unit for m in meta.values()} <= KNOWN_UNITS
    assert {d.unit for d in all_definitions()} <= KNOWN_UNITS
    for name, m in meta.items():
        assert m.doc.strip() == m.doc and "\n" not in m.doc and 10 <= len(m.doc) <= 100, name


def test_int32_bounds_are_whole_numbers(meta):
    types = {d.name: d.type for d in px4_catalog().defs}
    for name, m in meta.items():
        if types[name] is ParamType.INT32:
            assert all(b is None or b == int(b) for b in (m.min, m.max)), name


def test_the_registry_uses_the_metadata(meta):
    reg = default_registry()
    for d in reg:
        m = meta[d.name]
        assert d.doc == m.doc and (d.unit == m.unit or not m.unit), d.name
        assert m.min is None or d.min == m.min, d.name
        assert m.max is None or d.max == m.max, d.name
    assert reg.definition("SENS_BARO_QNH").unit == "hPa"
    assert (reg.definition("SENS_BARO_QNH").min, reg.definition("SENS_BARO_QNH").max) == (500, 1500)


def test_the_emulators_definitions_agree_with_px4s_stated_ranges_and_units(meta):
    """A definition may bound what PX4 leaves open (to keep the physics sane), never move a bound PX4 states."""
    for d in all_definitions():
        m = meta.get(d.name)
        if m is None:  # known but not listed (MIS_DIST_1WP...): its own description
            assert d.doc, d.name
            continue
        assert m.min is None or d.min == m.min, d.name
        assert m.max is None or d.max == m.max, d.name
        assert not m.unit or d.unit == m.unit, d.name


def test_a_value_outside_px4s_stated_range_is_refused_and_a_bound_accepted():
    reg = default_registry()
    with pytest.raises(ParamError, match=r"within \[500, 1500\]"):
        reg.set("SENS_BARO_QNH", 499.0)
    assert reg.get("SENS_BARO_QNH") == 1013.25
    with pytest.raises(ParamError, match="within"):
        reg.set("EKF2_REQ_NSATS", 13)
    assert reg.set("EKF2_REQ_NSATS", 12) == 12


def test_every_stated_bound_is_accepted_as_a_client_sends_it():
    """A REAL32 travels as float32: a client setting the bound 0.3 sends 0.30000001192..., which must be taken."""
    reg = default_registry()
    for d in list(reg):
        for bound in (d.min, d.max):
            if abs(bound) < 1e30:
                sent = bound if d.type is ParamType.INT32 else float32(bound)
                assert same_value(d.type, reg.set(d.name, sent), sent), d.name
        reg.reset([d.name])


def test_the_word_overlap_measure():
    tool = _tool()
    assert tool.word_overlap("Maximum horizontal velocity.", "Maximum horizontal velocity.\nLimits speed.") == 1.0
    assert tool.word_overlap("Absolute cap on ground speed", "Maximum horizontal velocity.") == 0.0
    assert tool.word_overlap("the speed of a climb", "Maximum climb speed") == 1.0  # stop words do not count


def test_the_tool_reproduces_the_file_and_no_description_repeats_px4s_words():
    source = next((path for path in REFERENCES if path.exists()), None)
    if source is None:
        pytest.skip("PX4's parameter reference is not on this machine (see tools/px4_param_meta.py).")
    tool = _tool()
    entries = tool.parse_reference(source.read_text(encoding="utf-8"))
    packaged = tool.TARGET.read_text(encoding="utf-8")
    names = [row["name"] for row in tool.read_table(tool.PARAMS.read_text(encoding="ascii"))]
    described = {row["name"]: row["description"] for row in tool.read_table(packaged)}
    text, problems = tool.build(entries, names, described)
    assert problems == [] and text == packaged
    worst = max(tool.word_overlap(described[n], tool.lookup(entries, n).text) for n in names)
    assert worst <= tool.MAX_OVERLAP
