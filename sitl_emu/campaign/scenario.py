"""A scenario and one case of it: load `module:function` or `path.py:function`, fly it against a fresh Sim, and turn
what happened (metrics, a refusal, an exception, the simulated-time limit) into one result row.

A scenario is `def fly(sim: Sim, case: Case) -> Outcome | Mapping`: it flies the user's own client against `sim`
(in lockstep: `sim.clock`, `sim.run_for`) and returns `Outcome(passed, {"name": value, ...})`, or a mapping of metrics
with a boolean "passed". Everything here runs in the worker, whichever engine started it; the row depends only on
the case and the scenario (the wall time excepted), as long as the scenario keeps no state from one case to the next
(a worker flies many cases) and draws its own randomness from `case.seed`. A scenario file's directory is added to
sys.path (last), so it may import the modules beside it.
"""

from __future__ import annotations

import contextlib
import functools
import importlib
import importlib.util
import inspect
import math
import sys
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from sitl_emu.campaign.cases import Case
from sitl_emu.campaign.errors import CampaignError

__all__ = ["Limits", "Outcome", "Row", "load_scenario", "prepare_worker", "run_case", "scenario_ref"]

Row = dict[str, Any]  # one case's result: see results.py for its columns
SIM_KEYWORDS_TAKEN = ("params", "seed")  # the case sets these itself


@dataclass(frozen=True)
class Outcome:
    """What a scenario returns: pass/fail and named numbers (`metrics`), with an optional one-line `note`. A metric
    the flight could not measure is None (or nan): an empty cell, left out of the quantiles, never a 0 that would
    look like the best case."""

    passed: bool
    metrics: Mapping[str, float | None] = field(default_factory=dict)
    note: str = ""


@dataclass(frozen=True)
class Limits:
    """Per case: at most `sim_s` simulated seconds and `wall_s` wall seconds (None: no limit)."""

    sim_s: float | None = 600.0
    wall_s: float | None = 300.0


class SimTimeLimit(BaseException):
    """Raised inside the scenario when the Sim would pass the case's simulated-time limit.

    A BaseException, so that a scenario's own `except Exception` does not swallow it.
    """


class WallTimeLimit(BaseException):
    """Raised in the case that passed its wall-time limit: by SIGALRM in the serial engine where there is one, else by
    the Sim's next step after the deadline (engines/serial.py). A BaseException for the same reason as SimTimeLimit.
    """


def scenario_ref(scenario: str | Callable[..., Any]) -> str:
    """The text form of a scenario, which every worker can load: `module:function` or `path.py:function`."""
    if isinstance(scenario, str):
        return scenario
    module = sys.modules.get(scenario.__module__)
    path = getattr(module, "__file__", None)
    if module is None or path is None or "<locals>" in scenario.__qualname__:
        raise CampaignError(f"scenario {scenario!r} must be a module-level function so that workers can load it.")
    if _importable_as(scenario.__module__, path):
        return f"{scenario.__module__}:{scenario.__qualname__}"
    return f"{Path(path).resolve()}:{scenario.__qualname__}"  # __main__, or a file imported by path


def _importable_as(module: str, path: str) -> bool:
    """True if a fresh process importing `module` gets the file `path` (not so for __main__ or pytest's modules)."""
    if module == "__main__":
        return False
    try:
        spec = importlib.util.find_spec(module)
    except (ImportError, ValueError):
        return False
    return spec is not None and spec.origin is not None and Path(spec.origin).resolve() == Path(path).resolve()


_LOADED: dict[str, Callable[..., Any]] = {}


def load_scenario(ref: str) -> Callable[..., Any]:
    """The function `ref` names; CampaignError with one sentence if it cannot be found."""
    if ref in _LOADED:
        return _LOADED[ref]
    where, sep, name = ref.rpartition(":")
    if not sep or not where or not name:
        raise CampaignError(f"scenario '{ref}' must look like module:function or path/to/file.py:function.")
    module = _load_file(where) if where.endswith(".py") else _import(where)
    function = getattr(module, name, None)
    if not callable(function):
        raise CampaignError(f"scenario '{ref}': {where} has no function {name}.")
    _LOADED[ref] = function
    return function


def _load_file(path_text: str) -> Any:
    path = Path(path_text).expanduser().resolve()
    if not path.is_file():
        raise CampaignError(f"scenario file {path_text} does not exist.")
    module_name = f"sitl_emu_scenario_{abs(hash(str(path)))}"
    spec = importlib.util.spec_from_file_location(module_name, path)
    if spec is None or spec.loader is None:
        raise CampaignError(f"scenario file {path_text} cannot be loaded as Python.")
    module = importlib.util.module_from_spec(spec)
    sys.modules[module_name] = module
    if str(path.parent) not in sys.path:
        sys.path.append(str(path.parent))
    try:
        spec.loader.exec_module(module)
    except Exception as err:
        del sys.modules[module_name]
        raise CampaignError(f"scenario file {path_text} fails to load: {one_line(err)}") from None
    return module


def _import(name: str) -> Any:
    try:
        return importlib.import_module(name)
    except ImportError as err:
        raise CampaignError(f"scenario module {name} cannot be imported: {one_line(err)}") from None


def one_line(err: BaseException) -> str:
    text = " ".join(str(err).split())
    return f"{type(err).__name__}: {text}" if text else type(err).__name__


def sim_options(options: Mapping[str, Any], sim_class: Any) -> dict[str, Any]:
    """The case options Sim takes as keywords (e.g. `wind`, once Sim has it); the others are the scenario's only."""
    accepted = _keywords(sim_class)
    return {k: v for k, v in options.items() if k in accepted and k not in SIM_KEYWORDS_TAKEN}


@functools.cache
def _keywords(sim_class: Any) -> frozenset[str]:
    return frozenset(inspect.signature(sim_class).parameters)


def prepare_worker(ref: str) -> None:
    """What a worker does once, before its first case, so that no case pays for it: import the Sim and the scenario,
    and build and close one Sim (its protocol handlers, parameter definitions and numpy's random generators are
    imported on first use). A scenario that cannot load is left to each case's error row."""
    from sitl_emu.testing import Sim

    with contextlib.suppress(CampaignError):
        load_scenario(ref)
    Sim().close()


def run_case(ref: str, case: Case, limits: Limits, wall_deadline_s: float | None = None) -> Row:
    """Fly `case` with the scenario `ref` in this process; never raises for the case's own failures.

    `wall_deadline_s` (a time.perf_counter() value): a step of the Sim after it raises WallTimeLimit, which is not
    caught here (the serial engine's wall-time limit where there is no SIGALRM)."""
    from sitl_emu.testing import Sim

    start = time.perf_counter()
    sim_s = 0.0
    try:
        scenario = load_scenario(ref)
        with Sim(params=case.params, seed=case.seed, **sim_options(case.options, Sim)) as sim:
            _limit_steps(sim, limits.sim_s, wall_deadline_s)
            try:
                outcome = scenario(sim, case)
            finally:
                sim_s = sim.time_us / 1e6
        row = outcome_row(outcome)
    except SimTimeLimit:
        row = failure_row("sim_limit", f"the case passed its limit of {limits.sim_s:g} simulated seconds.")
    except Exception as err:
        row = failure_row("error", one_line(err))
    row.update(sim_s=round(sim_s, 6), wall_s=round(time.perf_counter() - start, 3))
    return row


def _limit_steps(sim: Any, limit_s: float | None, wall_deadline_s: float | None = None) -> None:
    """Make every step of `sim` past `limit_s` raise SimTimeLimit, and every step after the wall-clock deadline raise
    WallTimeLimit (run_for, run_until and sim.clock all step here)."""
    if limit_s is None and wall_deadline_s is None:
        return
    advance = sim.advance_to
    limit_us = None if limit_s is None else round(limit_s * 1e6)

    def limited(target_us: int) -> None:
        if wall_deadline_s is not None and time.perf_counter() > wall_deadline_s:
            raise WallTimeLimit
        if limit_us is not None and target_us > limit_us:
            advance(limit_us)
            raise SimTimeLimit
        advance(target_us)

    sim.advance_to = limited


def outcome_row(outcome: Any) -> Row:
    """The status, note and metrics of what a scenario returned (an Outcome or a mapping with "passed")."""
    if isinstance(outcome, Mapping) and "passed" in outcome:
        metrics = {k: v for k, v in outcome.items() if k not in ("passed", "note")}
        outcome = Outcome(bool(outcome["passed"]), metrics, str(outcome.get("note", "")))
    if not isinstance(outcome, Outcome):
        return failure_row("error", f"the scenario returned {type(outcome).__name__}, not an Outcome or a mapping "
                                    "with 'passed'.")
    bad = [k for k, v in outcome.metrics.items()
           if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float)))]
    if bad:
        return failure_row("error", f"metric {bad[0]} is not a number: {outcome.metrics[bad[0]]!r}.")
    metrics = {f"metric.{k}": _measured(v) for k, v in outcome.metrics.items()}
    return {"status": "passed" if outcome.passed else "failed", "error": outcome.note, **metrics}


def _measured(value: float | None) -> float | None:
    """A metric's value, or None (an empty cell, left out of the quantiles) for one not measured: None, nan, inf."""
    return float(value) if value is not None and math.isfinite(value) else None


def failure_row(status: str, error: str) -> Row:
    return {"status": status, "error": error}
