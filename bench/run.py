"""Run the benchmarks and print one figure per line with its unit: `python -m bench [--quick] [--only NAME ...]`.

Figures (targets from issue 4 in brackets):
  core        simulated seconds per CPU second, one vehicle, fixed manoeuvre, no I/O [>= 1000]; and with I/O (the
              API link streaming to a scripted client in the process, the GCS link without a peer), with the
              floor that loopback UDP alone sets on this machine (bench/udp_floor.py)
  runner      the runners' own cost: a stub vehicle (no physics) at real time, % of one core and CPU per tick; the
              swarm runner's CPU per vehicle-tick with 100 stub vehicles (bench/runner.py)
  serve       `sitl-emu serve` at real time, hovering, default streams on both links: % of one core [<= 3.5], with
              the default batching (and the flight's ULog log, and --no-log), waking every tick, and --batch-ms 20;
              the log's size per minute of flight
  startup     wall time from process start to the first HEARTBEAT [< 0.5 s] and to health all good
  flight      reference loopback flight (arm, takeoff, OFFBOARD square, land) by a scripted pymavlink client:
              in-process lockstep wall time, and the highest `serve --speed` that still passes, with its wall time
  latency     joyfly joystick event -> setpoint datagram, median and p99 [p99 < 5 ms], the js reader's and the SDL
              path's side by side (bench/joyfly_latency.py)
  scale       largest --count N kept on time at real time on one core, hovering, default streams [100]
  view        `serve --view` at real time, hovering: % of one core of serve and of the Rerun viewer it starts (no
              browser connected), against serve without the view
  params      full parameter download (PARAM_REQUEST_LIST to the last PARAM_VALUE) from `serve` at real time, wall
              time [< 1 s; PX4 SITL 0.98 s] (bench/params.py)
  campaign    (not in the default set: ~2 min) cases per minute of a ~30 s simulated flight, local engine with 1 and 2
              workers and Ray with 2; Ray's overhead per case and ray.init's start-up; peak RSS per worker
              (bench/campaign.py)
Every figure is measured here and now; the machine line says how busy the host was.
"""

from __future__ import annotations

import argparse
import os
import platform
import re
import subprocess
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
if str(REPO) not in sys.path:  # `python bench/run.py`
    sys.path.insert(0, str(REPO))

from bench import campaign, params, runner, scale, serve, sides, udp_floor  # noqa: E402
from sitl_emu._speedups import PURE_ENV, build_line  # noqa: E402
from sitl_emu.cli.main import DEFAULT_BATCH_MS, wake_period_s  # noqa: E402

DEFAULT = ("core", "runner", "serve", "startup", "flight", "latency", "scale", "params", "view")
NAMES = (*DEFAULT, "campaign")


def say(line: str) -> None:
    print(line, flush=True)


def machine() -> None:
    model = next((ln.split(":", 1)[1].strip() for ln in Path("/proc/cpuinfo").read_text().splitlines()
                  if ln.startswith("model name")), platform.processor() or "?")
    load = " ".join(f"{x:.2f}" for x in os.getloadavg())
    say(f"machine: {model}, {os.cpu_count()} CPUs, load average {load}, Python {platform.python_version()}")
    say(f"build: {build_line()}; pure and compiled figures side by side below come from child processes that "
        f"alternate between the two builds ({PURE_ENV}=1 turns the compiled one off)")


def bench_core(quick: bool) -> None:
    runs = 1 if quick else 3
    pure, compiled = sides.side_by_side("core", runs)
    say(f"core: {sides.ratio_text(pure, compiled, 'simulated s per CPU s')} (one vehicle, the 36 s manoeuvre of "
        f"bench/core.py, no I/O, best of {runs}; target >= 1000, compiled >= 3000)")
    core = compiled if compiled is not None else pure
    pure, compiled = sides.side_by_side("core_io", runs)
    say(f"core with I/O: {sides.ratio_text(pure, compiled, 'simulated s per CPU s')} (same manoeuvre, MAVLink I/O "
        f"after every step as in a campaign case: the API link streams its default set to a scripted client in the "
        f"process that reads every 10 ms, CPU counted; the GCS link has no peer; best of {runs}; compiled target "
        f">= 500)")
    say(udp_floor.floor_text(core))


def bench_runner(quick: bool) -> None:
    seconds = 3.0 if quick else 10.0
    share, per_tick = runner.real_time_share(seconds)
    bare, per_wake = runner.real_time_share(seconds, streams=False)
    batched, _ = runner.real_time_share(seconds, wake_period_s(DEFAULT_BATCH_MS, 1.0))
    say(f"runner at real time, stub vehicle (no physics), default streams: {share:.1f} % of one core waking every "
        f"tick ({per_tick:.0f} us CPU per tick), {batched:.1f} % with the default --batch-ms {DEFAULT_BATCH_MS:g}; "
        f"streams off: {bare:.1f} % ({per_wake:.0f} us per tick and wake-up)")
    count = 100
    per_vehicle = runner.swarm_tick_cost(count, 1.0 if quick else 4.0)
    bare_vehicle = runner.swarm_tick_cost(count, 1.0 if quick else 4.0, streams=False)
    say(f"swarm runner, {count} stub vehicles, CPU-bound: {per_vehicle:.1f} us per vehicle-tick with default streams, "
        f"{bare_vehicle:.1f} us with streams off (runner + node + links alone)")


def bench_serve(quick: bool) -> None:
    seconds = 5.0 if quick else 30.0
    with tempfile.TemporaryDirectory() as logs:
        logging_on = ("--log-dir", logs)  # the default: a ULog of the flight (here not in the repository's log/)
        share = serve.hover_cpu_share(seconds, logging_on)
        say(f"serve at real time: {share:.1f} % of one core (hovering {seconds:.0f} s, default streams on both links, "
            f"default --batch-ms {DEFAULT_BATCH_MS:g}, logging the flight; target <= 3.5)")
        say(serve.log_size_line(Path(logs)))
    unlogged = serve.hover_cpu_share(seconds, ("--no-log",))
    say(f"serve at real time --no-log: {unlogged:.1f} % of one core (same, writing no ULog)")
    with tempfile.TemporaryDirectory() as logs:
        every_tick = serve.hover_cpu_share(seconds, ("--batch-ms", "0", "--log-dir", logs))
        say(f"serve at real time --batch-ms 0: {every_tick:.1f} % of one core (same, waking for every 4 ms tick as "
            "PX4 SITL does)")
        batched = serve.hover_cpu_share(seconds, ("--batch-ms", "20", "--log-dir", logs))
        say(f"serve at real time --batch-ms 20: {batched:.1f} % of one core (same, waking every 20 ms)")


def bench_view(quick: bool) -> None:
    seconds = 5.0 if quick else 30.0
    plain, _ = serve.hover_cpu_shares(seconds)
    viewed, viewer = serve.hover_cpu_shares(seconds, ("--view",))
    say(f"serve --view at real time: {viewed:.1f} % of one core (without the view: {plain:.1f} %), and its Rerun "
        f"viewer process {viewer:.1f} % (hovering {seconds:.0f} s, no browser connected)")


def bench_startup(quick: bool) -> None:
    runs = [serve.startup_times() for _ in range(1 if quick else 3)]
    first = min(r[0] for r in runs)
    healthy = min(r[1] for r in runs)
    say(f"start-up to first HEARTBEAT: {first:.3f} s wall (best of {len(runs)}; target < 0.5)")
    say(f"start-up to health all good: {healthy:.2f} s wall (includes the 2 s simulated estimator warm-up)")


def bench_flight(quick: bool) -> None:
    reference, wall = serve.lockstep_flight()
    if not reference.ok:
        say(f"loopback flight: the lockstep reference flight failed: {reference.error}")
        return
    pure, compiled = sides.side_by_side("flight", 1)
    say(f"loopback flight in-process lockstep: {wall:.2f} s wall for {reference.sim_duration_s:.1f} s simulated "
        f"({reference.sim_duration_s / wall:.0f}x real time in this process); in child processes: "
        f"{sides.ratio_text(pure, compiled, 'x real time')}")
    speeds = [10.0, 40.0, 100.0] if quick else [5.0, 10.0, 20.0, 40.0, 60.0, 80.0, 100.0]  # target: x100 passes
    attempts = serve.fastest_flight(speeds, reference)
    tried = ", ".join(f"x{s:g} {'ok' if ok else 'FAIL'} {w:.1f} s wall, vehicle at x{r.vehicle_duration_s / w:.0f}"
                      for s, ok, w, r in attempts)
    passed = [(s, w) for s, ok, w, _ in attempts if ok]
    failed = [r for _, ok, _, r in attempts if not ok]
    why = f"; failed: {failed[0].error or 'too slow, or other modes or landing point'}" if failed else ""
    if passed:
        best, best_wall = passed[-1]
        say(f"loopback flight via serve: highest passing speed x{best:g}, {best_wall:.2f} s wall ({tried}{why})")
    else:
        say(f"loopback flight via serve: no speed passed ({tried}{why})")


def bench_latency(quick: bool) -> None:
    script = REPO / "bench" / "joyfly_latency.py"
    out = subprocess.run([sys.executable, str(script), "--events", "100" if quick else "300"], cwd=REPO,
                         capture_output=True, text=True, timeout=900)
    found = {m.group(1): (m.group(2), m.group(3))
             for m in re.finditer(r"^(js|sdl) .*median ([\d.]+) ms, p99 ([\d.]+) ms", out.stdout, re.M)}
    if out.returncode != 0 or not found:
        say(f"joyfly latency: not measured ({(out.stderr or out.stdout).strip()[-200:]})")
        return
    for path, label in (("js", "js reader (a FIFO of js_event records)"), ("sdl", "SDL (a virtual game controller)")):
        if path in found:
            median, p99 = found[path]
            say(f"joyfly latency {path}: median {median} ms, p99 {p99} ms (target < 5; joystick event -> setpoint "
                f"datagram, {label})")
        else:
            say(f"joyfly latency {path}: not measured")


def bench_scale(quick: bool) -> None:
    cpu = sorted(os.sched_getaffinity(0))[-1]
    seconds = 3.0 if quick else 8.0
    best, trials = scale.search(8, 256, seconds, cpu)
    tried = ", ".join(f"{n} {'ok' if scale.on_time(r) else 'late'} ({r['cpu_share'] * 100:.0f} % cpu, "
                      f"lag {r['max_lag_s'] * 1000:.0f} ms)" for n, r in trials)
    ok = [(n, r) for n, r in trials if scale.on_time(r) and r["cpu_share"] > 0]
    estimate = f"; CPU-bound estimate {max(n / r['cpu_share'] for n, r in ok):.0f}" if ok else ""
    say(f"scale: {best} vehicles on one core at real time (hovering, default streams, {seconds:g} s trials on "
        f"CPU {cpu}; target 100{estimate}): {tried}")


def bench_params(quick: bool) -> None:
    runs = 1 if quick else 3
    seconds, count = params.download_time(runs)
    say(f"parameter download: {seconds:.3f} s wall for {count} parameters + _HASH_CHECK from serve at real time "
        f"(best of {runs}; target < 1, PX4 SITL 0.981 s)")


def bench_campaign(quick: bool) -> None:
    count = 4 if quick else 8
    local1 = campaign.run("local", 1, count)
    local2 = campaign.run("local", 2, count)
    ray2, init_s = campaign.run_ray(2, count)
    for r in (local1, local2, ray2):
        say(f"campaign {r.engine} x{r.workers}: {r.per_minute:.1f} cases per minute ({r.cases} cases of "
            f"{r.sim_s:.1f} s simulated, {r.passed} passed, {r.wall_s:.1f} s wall; {r.case_wall_s:.2f} s wall and "
            f"{r.case_cpu_s:.2f} s CPU per case inside the worker)")
    say(f"campaign local scaling 1 -> 2 workers: x{local2.per_minute / local1.per_minute:.2f} cases per minute")
    say(f"campaign ray overhead: {ray2.worker_s_per_case - local2.worker_s_per_case:+.2f} s per case (worker wall "
        f"per case, start-up and scheduling included, ray {ray2.worker_s_per_case:.2f} s - local "
        f"{local2.worker_s_per_case:.2f} s, 2 workers); ray.init {init_s:.2f} s once per campaign, not counted above")
    say(f"campaign peak RSS per worker: local {max(local1.peak_rss_mib, local2.peak_rss_mib):.0f} MiB, ray "
        f"{ray2.peak_rss_mib:.0f} MiB (the largest worker's getrusage ru_maxrss after its cases)")
    bench_campaign_builds(count)


def bench_campaign_builds(count: int) -> None:
    """The local engine with 2 workers, pure and compiled one after the other (the workers take the build)."""
    runs = {}
    for pure in (True, False) if sides.compiled_build_here() else (True,):
        with sides.build_for_children(pure):
            runs[pure] = campaign.run("local", 2, count)
    compiled = runs[False].per_minute if False in runs else None
    cpu = "" if compiled is None else f", compiled {runs[False].case_cpu_s:.2f}"
    say(f"campaign local x2, ~30 s flights: {sides.ratio_text(runs[True].per_minute, compiled, 'cases per minute')}; "
        f"CPU s per case: pure {runs[True].case_cpu_s:.2f}{cpu} (target: compiled >= 100 per minute)")


BENCHES: dict[str, Callable[[bool], None]] = {
    "core": bench_core, "runner": bench_runner, "serve": bench_serve, "startup": bench_startup, "flight": bench_flight,
    "latency": bench_latency, "scale": bench_scale, "params": bench_params, "view": bench_view,
    "campaign": bench_campaign,
}


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m bench", description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="shorter runs (~1 min in all)")
    parser.add_argument("--only", nargs="+", choices=NAMES, default=list(DEFAULT),
                        help="run only these (default: all but campaign)")
    args = parser.parse_args(argv)
    machine()
    for name in args.only:
        try:
            BENCHES[name](args.quick)
        except Exception as err:  # one broken benchmark must not hide the others
            say(f"{name}: failed: {type(err).__name__}: {err}")


if __name__ == "__main__":
    main()
