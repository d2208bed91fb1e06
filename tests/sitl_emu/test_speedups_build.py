"""How the compiled build is made (tools/build_speedups.py, setup.py) and how a run says which build it runs.

The fast tests compile nothing. The one that builds a wheel (a tiny module set, in tmp_path) runs only where a compiled
build is present, i.e. in `make compiled-check`, so the default suite stays quick.
"""

from __future__ import annotations

import hashlib
import importlib.machinery
import importlib.util
import json
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
from support import REPO_ROOT

from sitl_emu import _speedups

SUFFIX = importlib.machinery.EXTENSION_SUFFIXES[0]


def _load(name: str, path: Path):
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def build():
    return _load("build_speedups", REPO_ROOT / "tools" / "build_speedups.py")


def test_groups_split_the_modules_evenly_once_each_whatever_their_order(build):
    sources = list(build.DEFAULT_MODULES)
    assert build.group_count(1) == build.group_count(2) == build.MIN_GROUPS and build.group_count(16) == 16
    split = build.groups(sources, 4)
    assert [name for _, name in split] == [f"{build.GROUP}{i}" for i in range(4)]
    members = [rel for files, _ in split for rel in files]
    assert sorted(members) == sorted(sources)
    sizes = [sum((REPO_ROOT / rel).stat().st_size for rel in files) for files, _ in split]
    assert max(sizes) < 1.2 * min(sizes)
    assert build.groups(list(reversed(sources)), 4) == split
    assert build.groups(sources[:1], 4) == [(sources[:1], f"{build.GROUP}0")]


@pytest.mark.parametrize(("value", "level"), [("", None), ("0", "0"), ("3", "3"), (" 2 ", "2"), ("fast", None),
                                              ("4", None)])
def test_the_optimisation_level_comes_from_mypyc_opt_level_or_the_measured_default(build, value, level):
    assert build.opt_level({build.OPT_LEVEL_ENV: value}) == (level or build.DEFAULT_OPT_LEVEL)
    assert build.opt_level({}) == build.DEFAULT_OPT_LEVEL == "1"


def test_every_task_subclass_is_compiled_with_the_task_it_inherits(build):
    # an interpreted class cannot inherit from a compiled one: flight_tasks/core.py's Task and its subclasses go
    # together (the profile alone would leave auto.py, mission.py and rtl.py out)
    compiled = set(build.DEFAULT_MODULES)
    assert "sitl_emu/flight_tasks/core.py" in compiled
    for path in (REPO_ROOT / "sitl_emu").rglob("*.py"):
        text = path.read_text()
        if "(Task)" in text and "from sitl_emu.flight_tasks.core import" in text:
            assert path.relative_to(REPO_ROOT).as_posix() in compiled


def test_setup_py_compiles_nothing_unless_asked():
    env = {k: v for k, v in os.environ.items() if k != "SITL_EMU_COMPILE"}
    out = subprocess.run([sys.executable, "setup.py", "--name"], cwd=REPO_ROOT, env=env, capture_output=True,
                         text=True, timeout=120, check=True)
    assert out.stdout.strip().splitlines()[-1] == "joyfly"
    setup = (REPO_ROOT / "setup.py").read_text()
    assert "if compile_asked():" in setup and "mypyc" not in setup.split("if compile_asked():")[1].split("else:")[1]


def _fake_package(tmp_path: Path) -> Path:
    pkg = tmp_path / "fakepkg"
    pkg.mkdir()
    (pkg / "mod.py").write_text("X = 1\n")
    (pkg / f"mod{SUFFIX}").write_bytes(b"a build")
    (pkg / f"_native__mypyc{SUFFIX}").write_bytes(b"its shared library")

    def sha(path: Path) -> str:
        return hashlib.sha256(path.read_bytes()).hexdigest()

    manifest = {"compiled": {"fakepkg.mod": {"py": "fakepkg/mod.py", "py_sha256": sha(pkg / "mod.py"),
                                             "so": f"fakepkg/mod{SUFFIX}", "so_sha256": sha(pkg / f"mod{SUFFIX}")}},
                "shared_libs": [{"so": f"fakepkg/_native__mypyc{SUFFIX}",
                                 "so_sha256": sha(pkg / f"_native__mypyc{SUFFIX}")}],
                "depends": {}}
    (pkg / _speedups.MANIFEST_NAME).write_text(json.dumps(manifest))
    return pkg


def test_the_start_up_line_says_compiled_pure_or_why_not(tmp_path):
    pkg = _fake_package(tmp_path)
    assert _speedups.build_line(pkg, {}) == "core: compiled (mypyc), 1 module"
    assert _speedups.build_line(pkg, {_speedups.PURE_ENV: "1"}) == (
        "core: pure Python (SITL_EMU_PURE is set; 1 module compiled, not used)")
    (pkg / "mod.py").write_text("X = 2\n")
    assert _speedups.build_line(pkg, {}) == (
        "core: pure Python (the compiled build is stale; 1 module compiled, not used)")
    for built in pkg.glob(f"*{SUFFIX}"):
        built.unlink()
    assert _speedups.build_line(pkg, {}).startswith("core: pure Python (`make speedups` in a checkout, or "
                                                    "SITL_EMU_COMPILE=1 at pip install")


def test_campaign_says_at_start_which_build_runs(tmp_path):
    from click.testing import CliRunner

    from sitl_emu.cli.main import main

    scenario = tmp_path / "scenario.py"
    scenario.write_text("from sitl_emu.campaign import Outcome\n\n\ndef fly(sim, case):\n"
                        "    return Outcome(True, {})\n")
    result = CliRunner().invoke(main, ["campaign", "--scenario", f"{scenario}:fly", "--seed", "1", "--engine",
                                      "serial", "--out", "-", "--no-progress"])
    assert f"sitl-emu campaign: {_speedups.build_line()}" in result.output, result.output


def _compiled_build_here() -> bool:
    return _speedups.build_line().startswith("core: compiled")


@pytest.mark.compiled
@pytest.mark.skipif(not _compiled_build_here(), reason="builds a wheel: only in `make compiled-check`")
def test_a_wheel_built_with_sitl_emu_compile_runs_compiled(tmp_path):
    tree = tmp_path / "tree"
    tree.mkdir()
    for name in ("sitl_emu", "px4common", "joyfly", "flightview", "tools"):
        shutil.copytree(REPO_ROOT / name, tree / name, ignore=shutil.ignore_patterns("*.so", "__pycache__",
                                                                                    "_speedups_manifest.json"))
    for name in ("pyproject.toml", "setup.py", "README.md", "MANIFEST.in"):
        shutil.copy2(REPO_ROOT / name, tree / name)
    env = {**os.environ, "SITL_EMU_COMPILE": "sitl_emu/geo.py"}  # one small module: the mechanism, not the speed
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-build-isolation", "--no-deps", "-q", "-w",
                    str(tmp_path / "dist"), str(tree)], env=env, check=True, timeout=600)
    (wheel,) = (tmp_path / "dist").glob("joyfly-*.whl")
    assert not wheel.name.endswith("-none-any.whl")  # a platform wheel
    names = zipfile.ZipFile(wheel).namelist()
    assert f"sitl_emu/geo{SUFFIX}" in names and "sitl_emu/_speedups_manifest.json" in names
    target = tmp_path / "site"
    zipfile.ZipFile(wheel).extractall(target)
    probe = ("import sitl_emu.geo, sitl_emu._speedups as s; print(sitl_emu.geo.__file__); print(s.build_line())")
    out = subprocess.run([sys.executable, "-c", probe], cwd=tmp_path, env={**os.environ, "PYTHONPATH": str(target)},
                         capture_output=True, text=True, timeout=120, check=True)
    where, line = out.stdout.strip().splitlines()[-2:]
    assert where.endswith(SUFFIX) and where.startswith(str(target))
    assert line == "core: compiled (mypyc), 1 module"
    assert "stale" not in out.stderr
