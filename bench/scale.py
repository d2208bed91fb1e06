"""Scale: how many vehicles one process keeps on time at real time on ONE core, default streams on both links.

Each trial runs in a fresh child process pinned to one CPU (`python -m bench.scale N SECONDS`): N vehicles built as
`sitl-emu serve --count N` builds them (sitl_emu.runtime.swarm), all armed and taking off (then hovering), run by the
SwarmRunner at speed 1 with serve's default batching. The trial passes when the runner never had to drop time, the
slowest vehicle's simulated time never lagged the wall clock by more than LAG_LIMIT_S after the first second, and every
vehicle is still in the air at the end. CPU is this process's time over wall time: on a shared core a trial can be
late at well under 100 %, hence the CPU-bound estimate printed beside N.
"""

from __future__ import annotations

import json
import math
import os
import socket
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
LAG_LIMIT_S = 0.05
TAKEOFF_S = 5.0
HEADROOM = 0.9  # aim the next trial at 90 % of the CPU-bound estimate: the lag limit needs some slack


def trial(count: int, seconds: float, cpu: int | None = None) -> dict[str, float]:
    """Run one trial in a child process; its JSON result."""
    args = [sys.executable, "-m", "bench.scale", str(count), str(seconds)]
    if cpu is not None:
        args.append(str(cpu))
    out = subprocess.run(args, cwd=REPO, capture_output=True, text=True, timeout=300 + 3 * count,
                         env={**os.environ, "PYTHONPATH": str(REPO)})
    if out.returncode != 0:
        raise RuntimeError(f"scale trial with {count} vehicles failed: {out.stderr.strip()[-300:]}")
    return dict(json.loads(out.stdout.strip().splitlines()[-1]))


def on_time(result: dict[str, float]) -> bool:
    return result["dropped_s"] == 0 and result["max_lag_s"] <= LAG_LIMIT_S and result["airborne"] == result["count"]


def search(start: int, limit: int, seconds: float, cpu: int | None) -> tuple[int, list[tuple[int, dict[str, float]]]]:
    """Largest N kept on time, found in few trials: after each on-time trial, try the N its CPU share predicts
    (N / share x HEADROOM, at most 4 N); after a late one, bisect. Stops when the gap is within 1/8.
    Returns (largest passing N, all trials in order)."""
    trials: list[tuple[int, dict[str, float]]] = []
    good, bad, n = 0, limit + 1, min(start, limit)
    while True:
        result = trial(n, seconds, cpu)
        trials.append((n, result))
        if on_time(result):
            good = max(good, n)
            share = result["cpu_share"]
            guess = int(n / share * HEADROOM) if share > 0 else 2 * n
            n = min(max(guess, n + max(1, n // 8)), 4 * n, bad - 1, limit)  # at least the stopping gap onwards
        else:
            bad = min(bad, n)
            n = (good + bad) // 2
        if bad - good <= max(1, good // 8) or n <= good or n >= bad or any(n == m for m, _ in trials):
            return good, trials


def _worker(count: int, seconds: float, cpu: int | None) -> dict[str, float]:
    from sitl_emu.cli.main import DEFAULT_BATCH_MS, wake_period_s
    from sitl_emu.px4 import MavCmd
    from sitl_emu.runtime.swarm import SwarmRunner
    from sitl_emu.testing.sim import Sim
    from sitl_emu.types import VehicleCommand

    if cpu is not None:
        os.sched_setaffinity(0, {cpu})
    nan = math.nan
    sink = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)  # the remote nobody reads, for every link
    sink.bind(("127.0.0.1", 0))
    with sink, Sim(count=count) as sim:
        for node in sim.nodes:  # as serve: both links stream from boot (a Sim's link waits for a peer)
            node.api.link.remote = node.gcs.link.remote = sink.getsockname()
        # Boot, arm and take off without I/O (nobody listens yet; it halves the set-up): streams start with the runner
        for v in sim.vehicles:
            v.run_until(2_100_000)  # the simulated estimator warm-up
            v.handle_command(VehicleCommand(MavCmd.COMPONENT_ARM_DISARM, (1.0,) + (nan,) * 6))
            v.handle_command(VehicleCommand(MavCmd.NAV_TAKEOFF, (nan,) * 7))
            v.run_until(2_100_000 + round(TAKEOFF_S * 1e6))  # climbing; the timed part is the climb's end and hover
        runner = SwarmRunner(sim.nodes, speed=1.0)
        runner.min_wake_s = wake_period_s(DEFAULT_BATCH_MS, 1.0)  # as `sitl-emu serve --count N` runs them
        t0_sim = min(v.time_us for v in sim.vehicles)
        lag = {"max": 0.0}
        t0 = time.monotonic()
        cpu0 = time.process_time()

        def watch() -> None:
            elapsed = time.monotonic() - t0
            if elapsed > 1.0:
                behind = elapsed - (min(v.time_us for v in sim.vehicles) - t0_sim) / 1e6
                lag["max"] = max(lag["max"], behind)

        runner.hooks.append(watch)
        runner.run(duration_s=seconds)
        wall = time.monotonic() - t0
        airborne = sum(1 for v in sim.vehicles if v.snapshot().pos_ned_m[2] < -1.0)
        return {"count": count, "max_lag_s": round(lag["max"], 4), "dropped_s": runner.dropped_us / 1e6,
                "cpu_share": round((time.process_time() - cpu0) / wall, 3), "airborne": airborne}


if __name__ == "__main__":
    n_arg, s_arg = int(sys.argv[1]), float(sys.argv[2])
    cpu_arg = int(sys.argv[3]) if len(sys.argv) > 3 else None
    print(json.dumps(_worker(n_arg, s_arg, cpu_arg)))
