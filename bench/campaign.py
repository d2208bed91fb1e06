"""Campaign throughput (issue 16): N cases of a ~30 s simulated flight on the local engine (1 and 2 workers) and on
Ray (2 workers), timed from the driver.

The flight is examples/campaign_square.py with no square: take off in OFFBOARD to 3 m, hold HOLD_S, land. `fly`
below wraps it and adds, as metrics, the flight's CPU time and the worker's peak RSS so far (getrusage in the worker
itself, the same for both engines). Ray is started here before the campaign, so that ray.init's start-up is timed
apart from the cases; the workers' own start-up (spawn and imports for local, Ray's worker processes and the preload
task for Ray) is counted in the campaign's wall time, as a user sees it.
"""

from __future__ import annotations

import resource
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sitl_emu.campaign import Case, Outcome, make_cases, run_campaign
from sitl_emu.campaign.scenario import load_scenario

REPO = Path(__file__).resolve().parent.parent
EXAMPLE = f"{REPO / 'examples' / 'campaign_square.py'}:fly"
SELF = f"{Path(__file__).resolve()}:fly"  # by path: Ray's and spawn's workers load it without bench on sys.path
HOLD_S = 10.0  # with take-off, the OFFBOARD lead-in and landing to disarm: ~30 s simulated in all


def fly(sim: Any, case: Case) -> Outcome:
    """The example's flight, with its CPU seconds and the worker's peak resident memory (MiB) after it."""
    before = resource.getrusage(resource.RUSAGE_SELF)
    outcome: Outcome = load_scenario(EXAMPLE)(sim, case)
    after = resource.getrusage(resource.RUSAGE_SELF)
    cpu_s = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
    extra = {"cpu_s": cpu_s, "worker_peak_rss_mib": after.ru_maxrss / 1024}  # ru_maxrss: KiB on Linux
    return Outcome(outcome.passed, {**outcome.metrics, **extra}, outcome.note)


@dataclass
class Run:
    engine: str
    workers: int
    cases: int
    wall_s: float  # the whole campaign, from the driver
    passed: int
    sim_s: float  # mean simulated seconds per case
    case_wall_s: float  # mean wall seconds per case inside the worker (run_case's own clock)
    case_cpu_s: float  # mean CPU seconds of the flight itself (the scenario, not the Sim's set-up)
    peak_rss_mib: float  # the largest worker's peak RSS

    @property
    def per_minute(self) -> float:
        return 60.0 * self.cases / self.wall_s

    @property
    def worker_s_per_case(self) -> float:
        """Wall seconds each case costs one worker, start-up and scheduling included."""
        return self.wall_s * self.workers / self.cases


def flight_cases(count: int) -> list[Case]:
    return make_cases(fixed={"options.side_m": 0.0, "options.hold_s": HOLD_S}, grid={"seed": list(range(count))})


def run(engine: str, workers: int, count: int) -> Run:
    """Fly `count` cases on `engine` (with Ray already initialised when engine is "ray")."""
    rows: list[dict[str, Any]] = []
    start = time.perf_counter()
    run_campaign(SELF, flight_cases(count), engine=engine, workers=workers, on_row=rows.append)
    wall = time.perf_counter() - start
    return Run(engine, workers, count, wall, sum(bool(r["passed"]) for r in rows),
               _mean(rows, "sim_s"), _mean(rows, "wall_s"), _mean(rows, "metric.cpu_s"),
               max((float(r.get("metric.worker_peak_rss_mib") or 0.0) for r in rows), default=0.0))


def run_ray(workers: int, count: int) -> tuple[Run, float]:
    """(the Ray run, ray.init's wall seconds) on a local Ray started here with `workers` CPUs."""
    import ray

    start = time.perf_counter()
    ray.init(num_cpus=workers, include_dashboard=False, log_to_driver=False)
    init_s = time.perf_counter() - start
    try:
        return run("ray", workers, count), init_s
    finally:
        ray.shutdown()


def _mean(rows: list[dict[str, Any]], key: str) -> float:
    values = [float(r[key]) for r in rows if r.get(key) is not None]
    return sum(values) / len(values) if values else float("nan")
