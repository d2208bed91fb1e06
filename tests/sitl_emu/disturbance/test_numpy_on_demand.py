"""numpy is loaded only by a vehicle that draws from it (wind or estimate noise): a plain vehicle's process never
imports it, so it pays neither its import nor the CPU its BLAS threads spin for after it (issue 28)."""

from __future__ import annotations

import os
import subprocess
import sys

from support import REPO_ROOT

SCRIPT = """
import sys
from sitl_emu.vehicle.vehicle import Vehicle
from sitl_emu.disturbance.wind import WindSettings
v = Vehicle()
v.run_for(3.0)
plain = 'numpy' in sys.modules
Vehicle(wind=WindSettings(5.0, 270.0)).run_for(0.1)
print(plain, 'numpy' in sys.modules)
"""


def test_a_vehicle_without_wind_or_noise_never_imports_numpy() -> None:
    env = dict(os.environ, PYTHONPATH=str(REPO_ROOT))
    out = subprocess.run([sys.executable, "-c", SCRIPT], cwd=REPO_ROOT, env=env, capture_output=True, text=True,
                         timeout=60, check=True)
    assert out.stdout.split() == ["False", "True"]
