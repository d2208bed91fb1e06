"""`make demo` installs the package only (a light venv, quick on a fresh clone); `make test` adds the [test] extra,
also to a venv `make demo` made. Checked with `make -n` (what make would run) in a copy of the Makefile."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest
from support import REPO_ROOT

pytestmark = pytest.mark.skipif(shutil.which("make") is None, reason="make is not installed")


def planned(workdir: Path, target: str) -> str:
    """The commands `make TARGET` would run in `workdir` (a copy of the Makefile and pyproject.toml)."""
    env = {k: v for k, v in os.environ.items() if k not in ("MAKELEVEL", "MAKEFLAGS", "MFLAGS")}  # run by make test
    done = subprocess.run(["make", "-n", "--no-print-directory", target], cwd=workdir, env=env, capture_output=True,
                          text=True, timeout=30)
    assert done.returncode == 0, done.stderr
    return done.stdout


@pytest.fixture
def clone(tmp_path: Path) -> Path:
    for name in ("Makefile", "pyproject.toml"):
        shutil.copy(REPO_ROOT / name, tmp_path / name)
    return tmp_path


def test_demo_installs_the_package_without_the_test_extra(clone: Path) -> None:
    commands = planned(clone, "demo")
    assert "pip install --quiet --no-compile -e ." in commands
    assert "[test]" not in commands and "[view]" not in commands
    assert commands.rstrip().endswith("joyfly demo")


def test_test_after_demo_adds_the_test_extra(clone: Path) -> None:
    for line in planned(clone, "demo").splitlines():  # what `make demo` leaves: the venv and its stamp
        if line.startswith("touch "):
            stamp = clone / line.split()[1]
            stamp.parent.mkdir(parents=True, exist_ok=True)
            stamp.touch()
    commands = planned(clone, "test")
    assert "-m venv" not in commands  # the demo's venv is kept
    assert "-e '.[test]'" in commands
    assert "pytest" in commands


def test_test_runs_on_two_workers_and_test_fast_leaves_the_slow_ones_out(clone: Path) -> None:
    commands = planned(clone, "test")
    assert "pytest -q -n 2 --dist loadfile\n" in commands
    assert 'pytest -q -m "not slow"' in planned(clone, "test-fast")
