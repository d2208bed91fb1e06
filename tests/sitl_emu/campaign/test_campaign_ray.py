"""The Ray engine (issue 16): a 50-case campaign gives the same rows on a local Ray as on the process pool, and a
worker that dies or a case that hangs is that case's failure. Ray is the optional extra ray."""

from __future__ import annotations

import csv
import importlib.util
from collections.abc import Iterator
from pathlib import Path

import pytest
from support import campaign_scenarios

from sitl_emu.campaign import Limits, make_cases, run_campaign

pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(importlib.util.find_spec("ray") is None,
                                 reason="Ray is not installed here (pip install -e '.[ray]' runs these tests).")]

SCENARIOS = Path(campaign_scenarios.__file__).resolve()  # by path: Ray's workers do not have tests/ on sys.path


@pytest.fixture(scope="module")
def local_ray() -> Iterator[None]:
    import ray

    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    yield
    ray.shutdown()


def rows_of(path: Path) -> list[dict[str, str]]:
    with path.open(newline="") as f:
        return sorted(({k: v for k, v in r.items() if k != "wall_s"} for r in csv.DictReader(f)),
                      key=lambda r: r["case"])


def test_fifty_cases_give_the_same_rows_on_ray_as_on_the_process_pool(local_ray: None, tmp_path: Path) -> None:
    cases = make_cases({"options.run_s": 0.25, "options.estimate_noise": {"pos_white_m": 0.3}},
                       {"params.MPC_XY_CRUISE": [4.0, 6.0]},
                       {"seed": {"integers": [0, 10**6]}, "params.SIH_WIND_N": {"uniform": [0.0, 10.0]}}, 25, 11)
    assert len(cases) == 50
    ray_summary = run_campaign(f"{SCENARIOS}:hover", cases, tmp_path / "ray.csv", engine="ray")
    run_campaign(f"{SCENARIOS}:hover", cases, tmp_path / "local.csv", engine="local", workers=2)
    ray_rows = rows_of(tmp_path / "ray.csv")
    assert ray_rows == rows_of(tmp_path / "local.csv")
    assert len(ray_rows) == 50 and ray_summary.passed == 50
    assert len({r["metric.error_m"] for r in ray_rows}) == 50


def test_on_ray_a_dead_worker_and_a_hanging_case_fail_alone(local_ray: None, tmp_path: Path) -> None:
    cases = make_cases({"options.bad_seeds": [1]}, {"options.behave": ["die", "hang"], "seed": [0, 1, 2]})
    summary = run_campaign(f"{SCENARIOS}:misbehave", cases, tmp_path / "out.csv", engine="ray",
                           limits=Limits(sim_s=5.0, wall_s=15.0))
    rows = {(r["option.behave"], r["seed"]): r for r in rows_of(tmp_path / "out.csv")}
    assert rows[("die", "1")]["status"] == "crashed" and rows[("hang", "1")]["status"] == "timeout"
    assert all(rows[(b, s)]["status"] == "passed" for b in ("die", "hang") for s in ("0", "2"))
    assert (summary.total, summary.passed) == (6, 4)
