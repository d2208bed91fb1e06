"""The compiled build (`make speedups`) flies exactly as pure Python: same snapshots and events, bit for bit.

Skipped when nothing is compiled (the default). `make test` builds the speedups after the pure-Python run and runs
this file again, so CI checks both. The pure-Python reference runs in a child process with SITL_EMU_PURE=1.
"""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys

import pytest
from support import REPO_ROOT

import sitl_emu.control.attitude
import sitl_emu.physics
import sitl_emu.vehicle.vehicle  # noqa: F401  (imported so that compiled_modules() can see them)
from sitl_emu._speedups import compiled_modules

REPO = REPO_ROOT
HASH_SCRIPT = """
import hashlib, sys
sys.path.insert(0, {tests!r})
from support.flights import scripted_flight as _script
from sitl_emu.vehicle.vehicle import Vehicle
from sitl_emu._speedups import compiled_modules
print(len(compiled_modules()), hashlib.sha256(repr(_script(Vehicle(seed=7))).encode()).hexdigest())
"""

pytestmark = pytest.mark.skipif(not compiled_modules(), reason="no compiled build here (make speedups)")


def _child(pure: bool) -> tuple[int, str]:
    env = {k: v for k, v in os.environ.items() if k != "SITL_EMU_PURE"}
    if pure:
        env["SITL_EMU_PURE"] = "1"
    out = subprocess.run([sys.executable, "-c", HASH_SCRIPT.format(tests=str(REPO / "tests"))], cwd=REPO, env=env,
                         capture_output=True, text=True, timeout=120, check=True)
    count, digest = out.stdout.split()
    return int(count), digest


def test_the_vehicle_core_really_runs_compiled() -> None:
    names = compiled_modules()
    for module in ("sitl_emu.physics", "sitl_emu.control.attitude", "sitl_emu.vehicle.vehicle"):
        assert module in names


def test_compiled_and_pure_python_fly_identically() -> None:
    compiled_count, compiled_digest = _child(pure=False)
    pure_count, pure_digest = _child(pure=True)
    assert compiled_count > 0 and pure_count == 0
    assert compiled_digest == pure_digest


def test_in_process_run_matches_a_pure_python_child() -> None:
    from support.flights import scripted_flight as _script

    from sitl_emu.vehicle.vehicle import Vehicle

    digest = hashlib.sha256(repr(_script(Vehicle(seed=7))).encode()).hexdigest()
    assert digest == _child(pure=True)[1]
