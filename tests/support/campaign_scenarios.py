"""Scenarios for the campaign tests: a fast one whose numbers depend on the case's seed, parameters and faults, and
one that misbehaves as a case's `behave` option says (raise, hang in wall time, run past the simulated-time limit,
kill its worker), only for the seeds listed in `bad_seeds`."""

from __future__ import annotations

import math
import os
import time
from pathlib import Path
from typing import Any

from sitl_emu.campaign import Case, Outcome


def hover(sim: Any, case: Case) -> Outcome:
    """Stand on the ground for run_s with a noisy position estimate: the error is a function of the seed."""
    sim.run_for(float(case.options.get("run_s", 0.5)))
    vehicle = sim.vehicle(0)
    n, e, _ = vehicle.snapshot().pos_ned_m
    error = math.hypot(n, e)
    return Outcome(error < float(case.options.get("limit_m", 1.0)),
                   {"error_m": error, "cruise": vehicle.params.get("MPC_XY_CRUISE"), "faults": len(case.faults),
                    "sim_s": sim.time_us / 1e6})


def misbehave(sim: Any, case: Case) -> Outcome:
    if case.seed in case.options.get("bad_seeds", []):
        behave = case.options.get("behave")
        if behave == "raise":
            raise ValueError(f"boom in case {case.id}")
        if behave == "hang":
            time.sleep(600)
        if behave == "sim_hang":
            while True:
                sim.run_for(1.0)
        if behave == "slow_steps":  # wall time passes between the Sim's steps; gives up after 5 s
            end = time.perf_counter() + 5.0
            while time.perf_counter() < end:
                sim.run_for(0.01)
                time.sleep(0.01)
        if behave == "die":
            os._exit(3)
        if behave == "fail":
            return Outcome(False, {"error_m": 9.0}, note="too far")
        if behave == "wait_for_file":  # wall time passes while the file `wait_file` is there (a test's Ctrl-C)
            while Path(case.options["wait_file"]).exists():
                time.sleep(0.02)
        if behave == "unmeasured":  # cut short: nothing measured, as nan or as None
            return Outcome(False, {"error_m": math.nan, "cruise": None}, note="lost")
    return hover(sim, case)


def not_an_outcome(sim: Any, case: Case) -> Any:
    return 42
