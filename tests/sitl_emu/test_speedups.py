"""The opt-in compiled build (`make speedups`): a stale or foreign build is never used silently.

Nothing is compiled here: a fake package with a garbage "extension module" beside its .py stands in for a build, and
the manifest is written by hand to match it or not.
"""

from __future__ import annotations

import ast
import dataclasses
import hashlib
import importlib
import importlib.machinery
import importlib.util
import json
import logging
import sys
from pathlib import Path

import pytest
from support import REPO_ROOT

from sitl_emu import _speedups
from sitl_emu.commander.health_report import ReportInputs
from sitl_emu.navigator.geofence import GeofenceResult
from sitl_emu.physics import RIGID_BODY_FIELDS, RigidBodyState
from sitl_emu.px4 import NavState

SUFFIX = importlib.machinery.EXTENSION_SUFFIXES[0]
ROOT = REPO_ROOT


def _sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _fake_build(tmp_path: Path, name: str = "fakepkg") -> Path:
    """A package whose module `mod` has a .py and a (not loadable) extension module, with a matching manifest."""
    pkg = tmp_path / name
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "mod.py").write_text("WHERE = 'source'\n")
    (pkg / "helper.py").write_text("X = 1\n")
    (pkg / f"mod{SUFFIX}").write_bytes(b"not a real shared object")
    (pkg / f"_native__mypyc{SUFFIX}").write_bytes(b"not a real shared library either")
    manifest = {
        "compiled": {f"{name}.mod": {"py": f"{name}/mod.py", "py_sha256": _sha(pkg / "mod.py"),
                                     "so": f"{name}/mod{SUFFIX}", "so_sha256": _sha(pkg / f"mod{SUFFIX}")}},
        "shared_libs": [{"so": f"{name}/_native__mypyc{SUFFIX}", "so_sha256": _sha(pkg / f"_native__mypyc{SUFFIX}")}],
        "depends": {f"{name}/helper.py": _sha(pkg / "helper.py")},
    }
    (pkg / _speedups.MANIFEST_NAME).write_text(json.dumps(manifest))
    return pkg


def test_pure_tree_needs_no_fallback(tmp_path):
    pkg = tmp_path / "purepkg"
    pkg.mkdir()
    (pkg / "mod.py").write_text("")
    assert _speedups.plan(pkg, {}) == _speedups.Plan()


def test_a_build_that_matches_its_manifest_is_used(tmp_path):
    assert _speedups.plan(_fake_build(tmp_path), {}) == _speedups.Plan()


def test_an_edited_source_falls_back_to_the_py_with_a_warning(tmp_path):
    pkg = _fake_build(tmp_path)
    (pkg / "mod.py").write_text("WHERE = 'edited source'\n")
    decided = _speedups.plan(pkg, {})
    assert decided.sources == {"fakepkg.mod": str(pkg / "mod.py")}
    assert decided.warning is not None
    assert "fakepkg/mod.py changed" in decided.warning
    assert "make speedups" in decided.warning


def test_an_edited_dependency_also_makes_the_build_stale(tmp_path):
    pkg = _fake_build(tmp_path)
    (pkg / "helper.py").write_text("X = 2\n")
    decided = _speedups.plan(pkg, {})
    assert "fakepkg.mod" in decided.sources
    assert decided.warning is not None and "fakepkg/helper.py changed" in decided.warning


@pytest.mark.parametrize("damage", ["no manifest", "foreign module", "replaced binary", "missing binary"])
def test_a_foreign_or_incomplete_build_falls_back(tmp_path, damage):
    pkg = _fake_build(tmp_path)
    if damage == "no manifest":
        (pkg / _speedups.MANIFEST_NAME).unlink()
    elif damage == "foreign module":
        (pkg / f"helper{SUFFIX}").write_bytes(b"built by someone else")
    elif damage == "replaced binary":
        (pkg / f"mod{SUFFIX}").write_bytes(b"another build")
    else:
        (pkg / f"_native__mypyc{SUFFIX}").unlink()
    decided = _speedups.plan(pkg, {})
    assert "fakepkg.mod" in decided.sources
    assert decided.warning is not None and "make speedups" in decided.warning


def test_pure_env_var_bypasses_a_good_build_silently(tmp_path):
    decided = _speedups.plan(_fake_build(tmp_path), {_speedups.PURE_ENV: "1"})
    assert decided.sources == {"fakepkg.mod": str(tmp_path / "fakepkg" / "mod.py")}
    assert decided.warning is None


@pytest.fixture
def importable(tmp_path):
    """tmp_path on sys.path for the test; imported fake modules and installed finders removed afterwards."""
    sys.path.insert(0, str(tmp_path))
    finders = list(sys.meta_path)
    yield tmp_path
    sys.path.remove(str(tmp_path))
    sys.meta_path[:] = finders
    for name in [n for n in sys.modules if n.startswith("stalepkg")]:
        del sys.modules[name]
    importlib.invalidate_caches()


def test_guard_imports_the_source_instead_of_a_stale_extension_and_warns_once(importable, caplog):
    pkg = _fake_build(importable, "stalepkg")
    (pkg / "mod.py").write_text("WHERE = 'edited source'\n")
    importlib.invalidate_caches()
    with pytest.raises(ImportError):  # without the guard Python prefers the extension module beside the .py
        importlib.import_module("stalepkg.mod")
    sys.modules.pop("stalepkg.mod", None)
    with caplog.at_level(logging.WARNING, logger="sitl_emu"):
        _speedups.guard(pkg)
    assert importlib.import_module("stalepkg.mod").WHERE == "edited source"
    warnings = [r for r in caplog.records if r.levelno == logging.WARNING]
    assert len(warnings) == 1
    assert "run `make speedups` again" in warnings[0].getMessage().lower()


def test_rigid_body_field_tuple_lists_every_state_field():
    # vehicle.py copies a state with it: a compiled RigidBodyState has no __slots__ to read the names from.
    assert tuple(f.name for f in dataclasses.fields(RigidBodyState)) == RIGID_BODY_FIELDS


def _build_script():
    spec = importlib.util.spec_from_file_location("build_speedups", ROOT / "tools" / "build_speedups.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_build_records_every_source_the_compiled_modules_import():
    build = _build_script()
    deps = build.dependency_sources(list(build.DEFAULT_MODULES))
    assert "sitl_emu/__init__.py" in deps
    assert "sitl_emu/params/registry.py" in deps
    assert "sitl_emu/params/__init__.py" in deps
    assert "px4common/modes.py" in deps  # px4.py takes PX4's mode numbers from the shared package
    assert not set(deps) & set(build.DEFAULT_MODULES)
    assert all((ROOT / m).is_file() for m in build.DEFAULT_MODULES)


def test_build_flags_keep_floats_exact():
    assert "-ffp-contract=off" in _build_script().EXACT_FLOAT_FLAGS


def test_this_interpreter_reports_what_runs_compiled():
    import sitl_emu.physics  # noqa: F401

    names = _speedups.compiled_modules()
    assert _speedups.describe() == (f"compiled (mypyc): {len(names)} modules" if names else "pure Python")


@pytest.mark.parametrize("x", [0.0, -0.0, 1.5, -2.5e-300, 5e-324, 1.7976931348623157e308, -1.7976931348623157e308,
                               float("inf"), float("-inf"), float("nan"), 3, -7])
def test_the_controllers_isfinite_is_exactly_math_isfinite(x):
    # qmath.isfinite is arithmetic so that mypyc compiles it (it has no primitive for math.isfinite)
    import math

    from sitl_emu.control.qmath import isfinite

    assert isfinite(x) is math.isfinite(x)


def test_the_compiled_degrees_and_radians_give_maths_bits():
    # qmath.degrees / radians are the products CPython's math module computes, compiled without a boxed call
    import math
    import random
    import struct

    from sitl_emu.control.qmath import degrees, radians

    rng = random.Random(5)
    values = [0.0, -0.0, 5e-324, 1e-300, 1.7976931348623157e308, -1.7976931348623157e308, math.pi, -math.pi / 2,
              360.0, float("inf"), float("-inf"), float("nan")]
    values += [rng.uniform(-1e4, 1e4) for _ in range(2000)] + [rng.uniform(-7.0, 7.0) for _ in range(2000)]
    bits = struct.Struct("<d").pack
    for x in values:
        assert bits(degrees(x)) == bits(math.degrees(x)), x
        assert bits(radians(x)) == bits(math.radians(x)), x


def _written_out_dataclass_inits() -> list[tuple[str, ast.ClassDef, ast.FunctionDef]]:
    """Every @dataclass in sitl_emu that writes its own __init__ (for `make speedups`: mypyc compiles only those)."""
    found = []
    for path in sorted((ROOT / "sitl_emu").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if not isinstance(node, ast.ClassDef):
                continue
            if not any("dataclass" in ast.unparse(d) for d in node.decorator_list):
                continue
            init = next((f for f in node.body if isinstance(f, ast.FunctionDef) and f.name == "__init__"), None)
            if init is not None:
                found.append((f"{path.relative_to(ROOT)}:{node.name}", node, init))
    return found


def test_written_out_dataclass_inits_match_the_generated_ones():
    """A written-out __init__ takes the fields in their order, with their defaults (a default_factory: None), and
    sets each of them."""
    checked = _written_out_dataclass_inits()
    names = {name.split(":")[1] for name, _, _ in checked}
    assert {"VehicleSnapshot", "TrajectorySetpoint", "Decision", "CheckInputs"} <= names
    for name, cls, init in checked:
        fields = [s for s in cls.body if isinstance(s, ast.AnnAssign) and isinstance(s.target, ast.Name)
                  and "ClassVar" not in ast.unparse(s.annotation)]
        expected = []
        for f in fields:
            value = f.value
            if isinstance(value, ast.Call) and ast.unparse(value.func) == "field":
                factory = next((k for k in value.keywords if k.arg == "default_factory"), None)
                expected.append((f.target.id, "None" if factory is not None else None))
            else:
                expected.append((f.target.id, ast.unparse(value) if value is not None else None))
        args = init.args.args[1:] + init.args.kwonlyargs
        defaults = [None] * (len(init.args.args) - 1 - len(init.args.defaults)) + init.args.defaults
        defaults += init.args.kw_defaults
        written = [(a.arg, ast.unparse(d) if d is not None else None) for a, d in zip(args, defaults, strict=True)]
        assert written == expected, name
        assigned = [t.attr for stmt in init.body if isinstance(stmt, ast.Assign) for t in stmt.targets
                    if isinstance(t, ast.Attribute) and ast.unparse(t.value) == "self"]
        assert assigned == [f.target.id for f in fields], name  # every field set, in order


def _other_value(value: object) -> object:
    """A value of the same kind that differs from `value`."""
    if isinstance(value, bool):
        return not value
    if isinstance(value, NavState):
        return NavState.AUTO_RTL if value is not NavState.AUTO_RTL else NavState.AUTO_LAND
    if isinstance(value, int):
        return value + 1
    if isinstance(value, GeofenceResult):
        return dataclasses.replace(value, max_dist=not value.max_dist)
    raise AssertionError(f"no other value for {value!r}")


@pytest.mark.parametrize("instance", [
    GeofenceResult(max_alt=True, action=1),
    ReportInputs(NavState.AUTO_LOITER, True, 3, GeofenceResult(), False, 0, True, False, True),
], ids=lambda i: type(i).__name__)
def test_written_out_dataclass_comparisons_match_the_generated_ones(instance):
    """A written-out __eq__ (compiled by mypyc, unlike a generated one) is equal exactly when every field is."""
    assert instance == dataclasses.replace(instance)
    assert instance != object()
    for field in dataclasses.fields(instance):
        changed = dataclasses.replace(instance, **{field.name: _other_value(getattr(instance, field.name))})
        assert instance != changed, field.name
