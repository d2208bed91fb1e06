"""Campaigns through the Python API (issue 16): the same table from the process pool as from running the cases one
by one, a case that raises, hangs, overruns its simulated time or kills its worker is that case's failed row while
the others finish, and a rerun with the same output flies only what is missing."""

from __future__ import annotations

import csv
import importlib.util
from pathlib import Path
from typing import Any

import pytest
from support import REPO_ROOT, campaign_scenarios

from sitl_emu.campaign import CampaignError, Limits, make_cases, run_campaign

SCENARIOS = Path(campaign_scenarios.__file__).resolve()
NOISY = {"options.estimate_noise": {"pos_white_m": 0.3}}  # Sim(estimate_noise=...): a seeded estimate


def rows_of(path: Path) -> list[dict[str, str]]:
    with path.open(newline="") as f:
        return list(csv.DictReader(f))


def without_wall_time(rows: list[dict[str, str]]) -> list[dict[str, str]]:
    return sorted(({k: v for k, v in r.items() if k != "wall_s"} for r in rows), key=lambda r: r["case"])


@pytest.mark.slow
def test_the_process_pool_gives_the_same_table_as_running_the_cases_one_by_one(tmp_path: Path) -> None:
    cases = make_cases({**NOISY, "params.MPC_XY_CRUISE": 7.0, "faults": [[0.2, "gps_off"]]}, {"seed": [3, 4, 5, 6, 7]})
    serial = run_campaign(campaign_scenarios.hover, cases, tmp_path / "serial.csv", engine="serial")
    pooled = run_campaign(campaign_scenarios.hover, cases, tmp_path / "local.csv", engine="local", workers=2)
    serial_rows, pooled_rows = rows_of(tmp_path / "serial.csv"), rows_of(tmp_path / "local.csv")
    assert without_wall_time(pooled_rows) == without_wall_time(serial_rows)
    assert [r["case"] for r in serial_rows] == ["c0000", "c0001", "c0002", "c0003", "c0004"]
    errors = [float(r["metric.error_m"]) for r in serial_rows]
    assert len(set(errors)) == 5 and all(0 < e < 2.0 for e in errors)  # each seed its own noise
    first = serial_rows[0]
    assert (first["seed"], first["param.MPC_XY_CRUISE"], first["faults"]) == ("3", "7.0", "gps_off@0.2")
    assert (first["metric.cruise"], first["metric.faults"], first["metric.sim_s"]) == ("7.0", "1.0", "0.5")
    assert first["option.estimate_noise"] == '{"pos_white_m": 0.3}'
    assert first["sim_s"] == "0.5" and float(first["wall_s"]) > 0
    assert serial.total == pooled.total == 5 and serial.quantiles == pooled.quantiles


@pytest.mark.slow
def test_the_example_scenario_flies_pymavlink_the_same_in_the_pool_as_alone(tmp_path: Path) -> None:
    example = f"{REPO_ROOT / 'examples' / 'campaign_square.py'}:fly"
    options = {"options.side_m": 0.0, "options.alt_m": 1.5, "options.hold_s": 0.5, "options.max_error_m": 0.5,
               "options.estimate_noise": {"pos_white_m": 0.1}}
    cases = make_cases(options, {"seed": [1, 2]})
    alone = run_campaign(example, cases, tmp_path / "alone.csv", engine="serial")
    pooled = run_campaign(example, cases, tmp_path / "pool.csv", engine="local", workers=2)
    rows = rows_of(tmp_path / "alone.csv")
    assert without_wall_time(rows_of(tmp_path / "pool.csv")) == without_wall_time(rows)
    assert alone.passed == pooled.passed == 2, alone.text()
    holds = [float(r["metric.max_hold_error_m"]) for r in rows]
    assert holds[0] != holds[1] and all(0 < h < 0.5 for h in holds)
    assert all(8 < float(r["metric.flight_s"]) < 40 for r in rows)


@pytest.mark.slow
def test_a_case_that_raises_hangs_overruns_or_kills_its_worker_is_that_cases_failure(tmp_path: Path) -> None:
    behaviours = ["raise", "hang", "sim_hang", "die", "fail"]
    cases = make_cases({"options.bad_seeds": [1]}, {"options.behave": behaviours, "seed": [0, 1, 2]})
    out = tmp_path / "out.csv"
    summary = run_campaign(campaign_scenarios.misbehave, cases, out, workers=2, limits=Limits(sim_s=5.0, wall_s=8.0))
    rows = {(r["option.behave"], r["seed"]): r for r in rows_of(out)}
    assert len(rows) == 15
    expected = {"raise": "error", "hang": "timeout", "sim_hang": "sim_limit", "die": "crashed", "fail": "failed"}
    for behave, status in expected.items():
        bad = rows[(behave, "1")]
        assert (bad["status"], bad["passed"]) == (status, "false"), bad
        for seed in ("0", "2"):
            assert (rows[(behave, seed)]["status"], rows[(behave, seed)]["passed"]) == ("passed", "true")
    assert rows[("raise", "1")]["error"] == "ValueError: boom in case c0001"
    assert rows[("die", "1")]["error"] == "the worker process died (exit code 3) while flying this case."
    assert rows[("hang", "1")]["error"].startswith("the case passed its limit of 8 wall seconds")
    assert rows[("sim_hang", "1")]["error"] == "the case passed its limit of 5 simulated seconds."
    assert rows[("sim_hang", "1")]["sim_s"] == "5.0"
    assert rows[("fail", "1")]["error"] == "too far" and rows[("fail", "1")]["metric.error_m"] == "9.0"
    assert (summary.total, summary.passed) == (15, 10)
    assert summary.statuses == {"error": 1, "timeout": 1, "sim_limit": 1, "crashed": 1, "failed": 1}
    assert [w["status"] for w in summary.worst] == ["failed", "error", "timeout", "sim_limit", "crashed"]
    assert list(summary.reruns) == sorted(r["case"] for r in rows.values() if r["passed"] == "false")  # case order


@pytest.mark.slow
def test_a_rerun_with_the_same_output_flies_only_the_cases_it_lacks(tmp_path: Path) -> None:
    out = tmp_path / "out.csv"
    flown: list[str] = []
    run_campaign(campaign_scenarios.hover, make_cases(NOISY, {"seed": [0, 1, 2]}), out, engine="serial",
                 on_row=lambda row: flown.append(row["case"]))
    before = out.read_text()
    summary = run_campaign(campaign_scenarios.hover, make_cases(NOISY, {"seed": [0, 1, 2, 3, 4]}), out, workers=2,
                           on_row=lambda row: flown.append(row["case"]))
    assert flown[:3] == ["c0000", "c0001", "c0002"] and sorted(flown[3:]) == ["c0003", "c0004"]
    assert out.read_text().startswith(before) and len(rows_of(out)) == 5 and summary.total == 5
    run_campaign(campaign_scenarios.hover, make_cases(NOISY, {"seed": [0, 1, 2, 3, 4]}), out,
                 on_row=lambda row: flown.append(row["case"]))
    assert len(flown) == 5
    with pytest.raises(CampaignError, match=r"already holds case c0000 with other inputs; write to another --out"):
        run_campaign(campaign_scenarios.hover, make_cases(NOISY, {"seed": [9]}), out)


def test_a_metric_first_seen_late_widens_the_file_and_keeps_every_row(tmp_path: Path) -> None:
    out = tmp_path / "out.csv"
    cases = make_cases({"options.bad_seeds": [0], "options.behave": "raise"}, {"seed": [0, 1]})
    run_campaign(campaign_scenarios.misbehave, cases, out, engine="serial")
    rows = rows_of(out)
    assert [r["status"] for r in rows] == ["error", "passed"]
    assert rows[0]["metric.error_m"] == "" and float(rows[1]["metric.error_m"]) >= 0


def test_a_metric_a_failed_case_did_not_measure_is_empty_and_left_out_of_the_quantiles(tmp_path: Path) -> None:
    out = tmp_path / "out.csv"
    cases = make_cases({"options.bad_seeds": [0], "options.behave": "unmeasured"}, {"seed": [0, 1, 2]})
    summary = run_campaign(campaign_scenarios.misbehave, cases, out, engine="serial")
    rows = rows_of(out)
    assert [r["status"] for r in rows] == ["failed", "passed", "passed"]
    assert (rows[0]["metric.error_m"], rows[0]["metric.cruise"]) == ("", "")  # not nan, not 0
    errors = sorted(float(r["metric.error_m"]) for r in rows[1:])
    assert summary.quantiles["error_m"][0] == errors[0] and summary.quantiles["error_m"][-1] == errors[1]
    assert summary.left_out == {"error_m": 1, "cruise": 1, "faults": 1, "sim_s": 1}
    assert ("left out of the quantiles, without a value (a failed or missing metric):\n"
            "  error_m  in 1 of 3 cases\n  cruise   in 1 of 3 cases\n") in summary.text()
    assert "  c0000 failed (seed 0): lost\n" in summary.text()
    assert summary.worst[0]["case"] == "c0000"


@pytest.mark.slow
def test_the_example_scenario_cut_short_leaves_its_metrics_empty_not_zero(tmp_path: Path) -> None:
    example = f"{REPO_ROOT / 'examples' / 'campaign_square.py'}:fly"
    cases = make_cases({"options.side_m": 1000.0, "options.hold_s": 0.5}, {"seed": [1]})  # too far for 30 s
    summary = run_campaign(example, cases, tmp_path / "out.csv", engine="serial")
    [row] = rows_of(tmp_path / "out.csv")
    assert row["status"] == "failed" and row["error"].startswith("no arrival at (1000, 0)")
    assert (row["metric.max_hold_error_m"], row["metric.landing_offset_m"], row["metric.flight_s"]) == ("", "", "")
    assert summary.quantiles == {} and summary.left_out == {"max_hold_error_m": 1, "landing_offset_m": 1,
                                                            "flight_s": 1}


@pytest.mark.skipif(importlib.util.find_spec("pyarrow") is None, reason="pyarrow is not installed")
def test_the_parquet_copy_holds_the_same_typed_table(tmp_path: Path) -> None:
    import pyarrow.parquet as pq

    out = tmp_path / "out.csv"
    run_campaign(campaign_scenarios.hover, make_cases(NOISY, {"seed": [0, 1]}), out, engine="serial")
    table = pq.read_table(tmp_path / "out.parquet").to_pylist()
    csv_rows = rows_of(out)
    assert [r["case"] for r in table] == [r["case"] for r in csv_rows]
    assert [r["metric.error_m"] for r in table] == [float(r["metric.error_m"]) for r in csv_rows]
    assert [r["passed"] for r in table] == [True, True] and [r["seed"] for r in table] == [0, 1]


@pytest.mark.parametrize(("scenario", "message"), [
    ("no/such/file.py:fly", "scenario file no/such/file.py does not exist."),
    (f"{SCENARIOS}:nothing", f"scenario '{SCENARIOS}:nothing': {SCENARIOS} has no function nothing."),
    ("no_such_module_xyz:fly", "scenario module no_such_module_xyz cannot be imported: ModuleNotFoundError"),
    ("just_a_name", "scenario 'just_a_name' must look like module:function or path/to/file.py:function."),
])
def test_a_scenario_that_cannot_be_found_stops_the_campaign_before_anything_flies(scenario: str, message: str) -> None:
    with pytest.raises(CampaignError) as info:
        run_campaign(scenario, make_cases(), None)
    assert str(info.value).startswith(message)


def test_a_scenario_returning_something_else_is_an_error_row() -> None:
    rows: list[dict[str, Any]] = []
    run_campaign(campaign_scenarios.not_an_outcome, make_cases(), None, engine="serial", on_row=rows.append)
    assert rows[0]["status"] == "error" and "returned int, not an Outcome" in rows[0]["error"]
