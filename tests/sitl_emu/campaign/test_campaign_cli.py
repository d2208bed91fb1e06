"""`sitl-emu campaign` (issue 16): a small campaign file through the command line, its CSV, its summary, the command
that reruns a failed case alone, and one sentence for each mistake."""

from __future__ import annotations

import csv
import importlib.util
import shlex
from pathlib import Path

import pytest
from click.testing import CliRunner, Result
from support import campaign_scenarios

import sitl_emu.cli.main
from sitl_emu.campaign.engines.ray_engine import RAY_PACKAGES
from sitl_emu.cli.extras import install_command

SCENARIOS = Path(campaign_scenarios.__file__).resolve()

CAMPAIGN = f"""
scenario = "{SCENARIOS}:misbehave"
[limits]
sim_s = 20.0
wall_s = 60.0
[fixed]
params = {{ MPC_XY_CRUISE = 6.0 }}
options = {{ bad_seeds = [2], behave = "raise", estimate_noise = {{ pos_white_m = 0.2 }} }}
[grid]
seed = [1, 2]
[random]
count = 2
seed = 5
params = {{ SIH_WIND_N = {{ uniform = [0.0, 10.0] }} }}
"""


def run(*args: str) -> Result:
    return CliRunner().invoke(sitl_emu.cli.main.main, list(args), prog_name="sitl-emu")


@pytest.mark.slow
def test_a_campaign_file_through_the_command_line_gives_the_table_the_summary_and_the_reruns(tmp_path: Path) -> None:
    cases = tmp_path / "cases.toml"
    cases.write_text(CAMPAIGN)
    out = tmp_path / "out.csv"
    result = run("campaign", str(cases), "--out", str(out), "--workers", "2", "--no-progress")
    assert result.exit_code == 1, result.output  # a case failed
    with out.open(newline="") as f:
        rows = list(csv.DictReader(f))
    header = list(rows[0])
    assert header[:5] == ["case", "key", "seed", "faults", "param.MPC_XY_CRUISE"]
    assert header[5:10] == ["param.SIH_WIND_N", "option.bad_seeds", "option.behave", "option.estimate_noise",
                            "passed"]
    assert header[10:] == ["status", "error", "metric.error_m", "metric.cruise", "metric.faults", "metric.sim_s",
                           "sim_s", "wall_s"]
    assert [(r["case"], r["seed"], r["status"]) for r in sorted(rows, key=lambda r: r["case"])] == [
        ("c0000", "1", "passed"), ("c0001", "1", "passed"), ("c0002", "2", "error"), ("c0003", "2", "error")]
    winds = [float(r["param.SIH_WIND_N"]) for r in rows]
    assert len(set(winds)) == 4 and all(0 <= w <= 10 for w in winds)
    assert all(r["metric.cruise"] == "6.0" for r in rows if r["status"] == "passed")
    text = result.output
    assert "2 of 4 cases passed (50.0 %): 2 error" in text and "error_m" in text and f"results: {out}" in text
    reruns = [line.split(": ", 1)[1] for line in text.splitlines() if line.startswith(("  c0002: ", "  c0003: "))]
    assert len(reruns) == 2
    args = shlex.split(reruns[0])
    assert args[:2] == ["sitl-emu", "campaign"] and args[-4:] == ["--engine", "serial", "--out", "-"]
    again = run(*args[1:])
    assert again.exit_code == 1 and "0 of 1 cases passed (0.0 %): 1 error" in again.output
    assert "ValueError: boom in case c0000" in again.output  # alone, the case is the first one
    assert "results:" not in again.output
    rerun_all = run("campaign", str(cases), "--out", str(out), "--no-progress")
    assert rerun_all.exit_code == 1 and "2 of 4 cases passed" in rerun_all.output
    assert len(out.read_text().splitlines()) == 5  # nothing flew again


def test_cases_from_options_without_a_file_and_a_zero_exit_when_all_pass(tmp_path: Path) -> None:
    out = tmp_path / "x.csv"
    result = run("campaign", "--scenario", f"{SCENARIOS}:hover", "--seed", "4", "--seed", "5", "--param",
                 "MPC_XY_CRUISE=4.5", "--fault", "gps_off@0.1", "--option", "run_s=0.25", "--out", str(out),
                 "--engine", "serial")
    assert result.exit_code == 0, result.output
    with out.open(newline="") as f:
        rows = list(csv.DictReader(f))
    assert [(r["seed"], r["faults"], r["option.run_s"], r["metric.sim_s"]) for r in rows] == [
        ("4", "gps_off@0.1", "0.25", "0.25"), ("5", "gps_off@0.1", "0.25", "0.25")]


@pytest.mark.parametrize(("args", "message"), [
    (["campaign", "--seed", "1"], "no scenario: give --scenario module:function"),
    (["campaign", "--scenario", "missing.py:fly"], "scenario file missing.py does not exist."),
    (["campaign", "--scenario", f"{SCENARIOS}:hover", "--param", "SIH_WIND_X=3", "--out", "-"],
     "case c0000: Unknown parameter SIH_WIND_X."),
    (["campaign", "--scenario", f"{SCENARIOS}:hover", "--param", "SIH_WIND_N", "--out", "-"],
     "--param must look like NAME=NUMBER"),
    (["campaign", "--scenario", f"{SCENARIOS}:hover", "--fault", "gps_off", "--out", "-"],
     "--fault must look like NAME@SECONDS"),
    (["campaign", "--scenario", f"{SCENARIOS}:hover", "--fault", "gps_offf@3", "--out", "-"],
     "unknown fault 'gps_offf'"),
    (["campaign", "--scenario", f"{SCENARIOS}:hover", "--option", "side_m=nan", "--out", "-"],
     "options.side_m must be finite, not nan."),
    (["campaign", "--scenario", f"{SCENARIOS}:hover", "--option", "legs={n = [1.0, -inf]}", "--out", "-"],
     "options.legs must be finite, not -inf (in {'n': [1.0, -inf]})."),
    (["campaign", "no_such.toml"], "cannot read the campaign file no_such.toml: No such file or directory."),
    (["campaign", "--engine", "spark"], "Invalid value for '--engine'"),
])
def test_each_mistake_is_one_line(args: list[str], message: str) -> None:
    result = run(*args)
    lines = result.stderr.strip().splitlines()
    assert result.exit_code == 2 and len(lines) == 1, result.output
    assert lines[0].startswith(f"sitl-emu: {message}"), lines[0]


def test_a_toml_error_or_an_unknown_parameter_in_the_file_is_one_line_naming_the_file(tmp_path: Path) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text("scenario = 'x.py:f'\n[grid\n")
    lines = run("campaign", str(bad)).stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"sitl-emu: {bad} is not valid TOML: ")
    bad.write_text(f"scenario = '{SCENARIOS}:hover'\n[fixed]\nparams = {{ NO_SUCH_PARAM = 1 }}\n")
    result = run("campaign", str(bad), "--out", "-")
    assert result.stderr.strip() == "sitl-emu: case c0000: Unknown parameter NO_SUCH_PARAM."
    result = run("campaign", str(bad), "--seed", "3")
    assert "give the cases either in CASES.toml or with --seed" in result.stderr
    bad.write_bytes(bytes(range(256)))
    lines = run("campaign", str(bad)).stderr.strip().splitlines()
    assert lines == [f"sitl-emu: {bad} is not a text file: a campaign file is TOML (UTF-8 text)."]


def test_a_results_file_that_cannot_be_written_is_one_line(tmp_path: Path) -> None:
    blocker = tmp_path / "a_file"
    blocker.write_text("")
    out = blocker / "results.csv"  # its folder would be a regular file
    result = run("campaign", "--scenario", f"{SCENARIOS}:hover", "--seed", "1", "--out", str(out))
    lines = result.stderr.strip().splitlines()
    assert result.exit_code == 2 and len(lines) == 1, result.output
    assert lines[0].startswith(f"sitl-emu: cannot write the results file {out}: "), lines[0]


def test_a_results_file_in_a_missing_folder_is_refused_not_created(tmp_path: Path) -> None:
    out = tmp_path / "no" / "such" / "x.csv"
    result = run("campaign", "--scenario", f"{SCENARIOS}:hover", "--seed", "1", "--out", str(out))
    assert result.exit_code == 2, result.output
    assert result.stderr.strip() == (f"sitl-emu: cannot write the results file {out}: the folder {out.parent} does "
                                     "not exist; create it or choose another --out.")
    assert not (tmp_path / "no").exists()


def test_the_ray_engine_without_ray_or_with_no_cluster_at_the_address_is_one_line(tmp_path: Path) -> None:
    result = run("campaign", "--scenario", f"{SCENARIOS}:hover", "--engine", "ray", "--address", "127.0.0.1:1",
                 "--out", str(tmp_path / "x.csv"))
    lines = result.stderr.strip().splitlines()
    assert result.exit_code == 2 and len(lines) == 1, result.output
    if importlib.util.find_spec("ray") is None:
        assert lines[0] == ("sitl-emu: the ray engine needs Ray, which is not installed: "
                            f"{install_command('ray', RAY_PACKAGES)}, or use --engine local.")
    else:
        assert lines[0].startswith("sitl-emu: no Ray cluster answers at 127.0.0.1:1 (")
    assert not (tmp_path / "x.csv").exists()  # refused before anything was written
