"""Campaign cases (issue 16): grids, seeded draws, timed faults and the campaign file, and one sentence for each
mistake, all before anything flies."""

from __future__ import annotations

from pathlib import Path

import pytest

from sitl_emu.campaign import CampaignError, CaseError, FaultDraw, FaultSchedule, make_cases, parse_fault, read_spec
from sitl_emu.campaign.cases import check_params
from sitl_emu.campaign.spec import tomllib
from sitl_emu.campaign.summary import toml_value

EXAMPLE = Path(__file__).resolve().parents[3] / "examples" / "campaign_square.toml"


def test_a_grid_times_draws_gives_every_combination_with_its_own_seed_and_reproducible_draws() -> None:
    kwargs = dict(fixed={"params.SYS_FAILURE_EN": 1}, grid={"params.SIH_WIND_N": [0.0, 5.0], "options.side_m": [1, 2]},
                  draws={"params.SIH_WIND_E": {"uniform": [-5.0, 5.0]}, "options.k": {"choice": ["a", "b"]}},
                  count=3, draw_seed=7, fault_draws=[FaultDraw("gps_off", {"uniform": [10.0, 20.0]}, 0.5)])
    cases = make_cases(**kwargs)  # type: ignore[arg-type]
    assert len(cases) == 2 * 2 * 3
    assert [c.id for c in cases[:2]] == ["c0000", "c0001"] and [c.seed for c in cases] == list(range(12))
    assert {(c.params["SIH_WIND_N"], c.options["side_m"]) for c in cases} == {(0, 1), (0, 2), (5, 1), (5, 2)}
    assert all(c.params["SYS_FAILURE_EN"] == 1 and -5 <= c.params["SIH_WIND_E"] <= 5 for c in cases)
    assert len({c.params["SIH_WIND_E"] for c in cases}) == 12
    with_fault = [c for c in cases if c.faults]
    assert 0 < len(with_fault) < 12 and all(10 <= c.faults[0].t_s <= 20 for c in with_fault)
    assert make_cases(**kwargs) == cases  # type: ignore[arg-type]
    assert [c.key for c in make_cases(**kwargs)] == [c.key for c in cases]  # type: ignore[arg-type]
    other = make_cases(**{**kwargs, "draw_seed": 8})  # type: ignore[arg-type]
    assert [c.params["SIH_WIND_E"] for c in other] != [c.params["SIH_WIND_E"] for c in cases]
    more = make_cases(**{**kwargs, "grid": {"params.SIH_WIND_N": [0.0, 5.0], "options.side_m": [1, 2, 3]}})
    assert more[:3] == cases[:3]  # a case draws from its own generator: its draws do not move when cases are added


def test_faults_are_mavlink_failure_units_and_types_handed_out_once_when_due() -> None:
    gps = parse_fault(12, "gps_off")
    motor = parse_fault(5.5, "Motor_off:2")
    assert gps.command_params()[:3] == (4.0, 1.0, 0.0)  # FAILURE_UNIT_SENSOR_GPS, FAILURE_TYPE_OFF, all instances
    assert (motor.name, motor.command_params()[:3]) == ("motor_off:2", (101.0, 1.0, 2.0))
    assert parse_fault(0, "mavlink_signal_off").unit == 105 and parse_fault(0, "gps_ok").type == 0
    schedule = FaultSchedule([gps, motor])
    assert schedule.due(5.0) == [] and schedule.due(6.0) == [motor] and schedule.due(6.0) == []
    assert schedule.due(100.0) == [gps] and schedule.pending == 0
    with pytest.raises(CaseError, match="unknown fault 'gps_of'; write UNIT_TYPE"):
        parse_fault(1, "gps_of")
    with pytest.raises(CaseError, match="time must be a number of seconds >= 0"):
        parse_fault(-1, "gps_off")


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"grid": {"wind": [1]}}, "'wind' is not a case input; use seed, faults, params.NAME or options.NAME."),
    ({"grid": {"seed": []}}, "grid seed must be a non-empty list"),
    ({"draws": {"params.A": {"gauss": [0, 1]}}, "count": 2}, "random params.A must be one of uniform, normal"),
    ({"draws": {"params.A": {"uniform": [0]}}, "count": 2}, "uniform needs two numbers"),
    ({"fixed": {"seed": -1}}, "seed must be a whole number >= 0"),
    ({"fixed": {"params.A": "x"}}, "params.A must be a finite number"),
    ({"fixed": {"faults": [[1.0]]}}, "a fault must be a pair"),
])
def test_a_badly_written_case_is_one_sentence(kwargs: dict, message: str) -> None:
    with pytest.raises(CaseError, match=message.replace("(", r"\(").replace("[", r"\[")):
        make_cases(**kwargs)


def test_unknown_parameters_and_values_out_of_range_are_refused_with_pxs_words() -> None:
    check_params(make_cases(fixed={"params.SIH_WIND_N": 5.0, "params.SYS_FAILURE_EN": 1}))
    with pytest.raises(CaseError, match=r"^case c0000: Unknown parameter SIH_WIND_X\.$"):
        check_params(make_cases(fixed={"params.SIH_WIND_X": 5.0}))
    with pytest.raises(CaseError, match=r"^case c0000: Parameter MPC_XY_CRUISE must be within"):
        check_params(make_cases(fixed={"params.MPC_XY_CRUISE": -3.0}))


def test_the_example_campaign_file_is_200_square_flights_under_wind_with_gps_dropouts() -> None:
    spec = read_spec(EXAMPLE)
    assert spec.scenario == f"{EXAMPLE.with_suffix('.py')}:fly"
    assert len(spec.cases) == 200 and (spec.limits.sim_s, spec.limits.wall_s) == (180.0, 120.0)
    winds = {c.params["SIH_WIND_N"] for c in spec.cases}
    assert winds == {0.0, 2.5, 5.0, 7.5, 10.0}
    faulted = [c for c in spec.cases if c.faults]
    assert 60 < len(faulted) < 140 and all(f.name == "gps_off" and 15 <= f.t_s <= 30 for c in faulted for f in c.faults)
    check_params(spec.cases)


@pytest.mark.parametrize(("text", "message"), [
    ("scenario = 'a.py:f'\n[grid\n", "is not valid TOML: "),
    ("scenario = 'a.py:f'\nwind = 3\n",
     "unknown key 'wind'; a campaign file has fixed, grid, limits, random, scenario."),
    ("[limits]\nwall_s = 0\n", "limits.wall_s must be a number of seconds > 0"),
    ("[random]\ncount = -2\n", "random.count must be a whole number >= 0"),
    ("[[random.faults]]\nname = 'gps_off'\n", "each [[random.faults]] needs name and at"),
    ("[fixed]\nparams = { A = true }\n", "params.A must be a finite number"),
    ("[fixed]\noptions = { side_m = nan }\n", "options.side_m must be finite, not nan."),
    ("[grid]\noptions = { wind = [[1.0, inf]] }\n", "options.wind must be finite, not inf (in [1.0, inf])."),
])
def test_a_mistake_in_the_campaign_file_is_one_sentence_naming_the_file(tmp_path: Path, text: str,
                                                                         message: str) -> None:
    path = tmp_path / "cases.toml"
    path.write_text(text)
    with pytest.raises(CampaignError) as info:
        read_spec(path)
    assert str(info.value).startswith(str(path)) and message in str(info.value)
    assert "\n" not in str(info.value)


def test_a_campaign_file_without_grid_or_draws_is_one_case_and_faults_may_be_fixed(tmp_path: Path) -> None:
    path = tmp_path / "one.toml"
    path.write_text("scenario = 'pkg.mod:fly'\n[fixed]\nseed = 9\n"
                    "faults = [[3.0, 'gps_off'], [1.0, 'rc_signal_off']]\n")
    spec = read_spec(path)
    assert spec.scenario == "pkg.mod:fly"
    assert len(spec.cases) == 1 and spec.cases[0].seed == 9
    assert [(f.t_s, f.name) for f in spec.cases[0].faults] == [(1.0, "rc_signal_off"), (3.0, "gps_off")]


@pytest.mark.parametrize("value", [1.5, 3, "gps", True, [1, 2.5], {"a": 1, "b": [True]}])
def test_an_option_value_goes_through_the_rerun_command_as_toml_and_comes_back_the_same(value: object) -> None:
    assert tomllib.loads(f"v = {toml_value(value)}")["v"] == value
