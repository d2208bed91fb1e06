"""A campaign worker does its start-up once (scenario.prepare_worker, issue 28): after it, a case imports nothing of
the emulator, numpy or pymavlink, and scipy is never imported for a case without turbulence."""

from __future__ import annotations

import json
import os
import subprocess
import sys

from support import REPO_ROOT, campaign_scenarios

SCRIPT = """
import json, sys
from sitl_emu.campaign import make_cases
from sitl_emu.campaign.scenario import Limits, prepare_worker, run_case
ref = sys.argv[1]
cases = make_cases(grid={"seed": [1, 2]})  # made by the campaign's driver, not its workers
prepare_worker(ref)
before = set(sys.modules)
rows = [run_case(ref, case, Limits()) for case in cases]
print(json.dumps({"new": sorted(set(sys.modules) - before), "status": [r["status"] for r in rows],
                  "scipy": "scipy" in sys.modules}))
"""


def test_after_the_workers_start_up_a_case_imports_nothing_of_the_emulator():
    ref = f"{campaign_scenarios.__file__}:hover"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO_ROOT), str(REPO_ROOT / "tests")])}
    out = subprocess.run([sys.executable, "-c", SCRIPT, ref], cwd=REPO_ROOT, env=env, capture_output=True, text=True,
                         timeout=120, check=True)
    result = json.loads(out.stdout.strip().splitlines()[-1])
    assert result["status"] == ["passed", "passed"]
    assert [m for m in result["new"] if m.split(".")[0] in ("sitl_emu", "numpy", "pymavlink", "scipy")] == []
    assert not result["scipy"]
