"""Run a campaign: check everything first (the scenario loads, every parameter exists), skip the cases the results
file already holds, fly the others on the engine, write each row as it arrives, and summarize the whole table.

    from sitl_emu.campaign import make_cases, run_campaign
    summary = run_campaign("examples/campaign_square.py:fly", make_cases(grid={"seed": [0, 1, 2]}), "out.csv")
    print(summary.text())
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from contextlib import AbstractContextManager, nullcontext
from pathlib import Path
from typing import Any

from sitl_emu.campaign.cases import Case, check_params
from sitl_emu.campaign.engines import Engine, make_engine
from sitl_emu.campaign.errors import CampaignError, CampaignInterrupted
from sitl_emu.campaign.results import ResultsFile, case_columns, input_columns, typed, write_parquet
from sitl_emu.campaign.scenario import Limits, Row, load_scenario, scenario_ref
from sitl_emu.campaign.summary import Summary, rerun_command, summarize

__all__ = ["run_campaign"]

Progress = Callable[[int], AbstractContextManager[Any]]  # given the number of cases to run; .update(1) per case


def run_campaign(scenario: str | Callable[..., Any], cases: Sequence[Case], out: str | Path | None = None, *,
                 engine: str | Engine = "local", workers: int | None = None, address: str | None = None,
                 limits: Limits | None = None, progress: Progress | None = None, worst_by: str | None = None,
                 on_row: Callable[[Row], None] | None = None) -> Summary:
    """Fly every case of `cases` not yet in `out` (a CSV path; None keeps the rows in memory only) and summarize
    every case's row. Raises CampaignError, before any case flies, for a scenario or a case that cannot work, and
    CampaignInterrupted (a KeyboardInterrupt holding the summary so far) on Ctrl-C."""
    ref = scenario_ref(scenario)
    load_scenario(ref)
    _check_ids(cases)
    check_params(cases)
    limits = limits or Limits()
    runner = make_engine(engine, workers, address) if isinstance(engine, str) else engine
    results = ResultsFile(Path(out) if out is not None else None, input_columns(cases))
    done = results.finished(cases)
    todo = [c for c in cases if c.id not in done]
    flown = 0
    try:
        with (progress(len(todo)) if progress else nullcontext()) as bar:
            for case, row in _guarded(runner.run(ref, todo, limits)):
                full = {**case_columns(case), "passed": row.get("status") == "passed", **row}
                results.add(full)
                flown += 1
                if bar is not None:
                    bar.update(1)
                if on_row is not None:
                    on_row(full)
    except KeyboardInterrupt:  # Ctrl-C: every finished row is on disk; say what they show
        raise CampaignInterrupted(_summary(results, cases, ref, limits, worst_by), flown, len(todo)) from None
    finally:
        if results.path is not None and flown:
            write_parquet(results.path)
    return _summary(results, cases, ref, limits, worst_by)


def _guarded(rows: Iterator[tuple[Case, Row]]) -> Iterator[tuple[Case, Row]]:
    """The engine's rows; the engine's generator is closed (its workers stopped) however the loop ends."""
    try:
        yield from rows
    finally:
        close = getattr(rows, "close", None)
        if close is not None:
            close()


def _check_ids(cases: Sequence[Case]) -> None:
    seen: set[str] = set()
    for case in cases:
        if case.id in seen:
            raise CampaignError(f"two cases are named {case.id}; give every case its own id.")
        seen.add(case.id)


def _summary(results: ResultsFile, cases: Sequence[Case], ref: str, limits: Limits,
             worst_by: str | None) -> Summary:
    ids = {c.id: c for c in cases}
    rows = [typed(r) for r in results.rows if r.get("case") in ids]
    summary = summarize(rows, worst_by)
    failed = sorted(r["case"] for r in rows if not r["passed"])  # in case order, not the order they finished
    summary.reruns = {case: rerun_command(ref, ids[case], limits) for case in failed}
    return summary
