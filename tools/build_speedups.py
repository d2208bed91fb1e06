"""`make speedups`: compile the hot modules of sitl_emu in place with mypyc (opt-in, never by default).

usage: .venv/bin/python tools/build_speedups.py [--clean] [MODULE.py ...]

The compiled extension modules are written next to their sources (sitl_emu/.../*.so), plus one shared library per
compilation group (sitl_emu/_speedups_native<N>__mypyc*.so) and a manifest (sitl_emu/_speedups_manifest.json) that
records the sha256 of every source the build read. At import time sitl_emu/_speedups.py compares the manifest with
the sources and falls back to the pure-Python modules, with one warning, when anything changed since the build.
setup.py builds the same modules the same way for `SITL_EMU_COMPILE=1 pip install .` and `python -m build`.

Build time (README, "The compiled build"): the modules are the ones a profile finds the time in (DEFAULT_MODULES),
mypyc compiles them in separate groups (each its own C file and shared library) that the C compilers build side by
side (build_ext --parallel), at MYPYC_OPT_LEVEL (default DEFAULT_OPT_LEVEL, the level that pays).

Exactness: the C compiler must evaluate every float expression as written. -ffp-contract=off forbids fusing a*b+c into
one FMA (which rounds once instead of twice); nothing here passes -march=native or -ffast-math, and CFLAGS from the
environment are ignored so they cannot bring either in.
"""

from __future__ import annotations

import ast
import hashlib
import json
import os
import subprocess
import sys
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = "sitl_emu"
SHARED = "px4common"  # the package sitl_emu shares with joyfly: compiled modules import it, so the manifest tracks it
GROUP = "sitl_emu._speedups_native"  # shared libraries: sitl_emu/_speedups_native<N>__mypyc<EXT_SUFFIX>, one a group
MANIFEST = ROOT / PACKAGE / "_speedups_manifest.json"
BUILD_DIR = Path("build") / "mypyc"

# The modules that hold the time of a lockstep flight, chosen by profile (cProfile, own time per source file, the
# manoeuvre of `python -m bench --only core` with MAVLink I/O, and one case of bench/campaign.py's campaign flight;
# README, "The compiled build"): every module at 0.3 % or more in either, the share in brackets (I/O run, campaign).
# Below that line a module's C compile costs more build time than it gives back. CORE_MODULES are the controllers and
# the physics, the fallback set when the full set does not compile.
CORE_MODULES = (
    "sitl_emu/control/qmath.py",  # 9.1, 4.6
    "sitl_emu/physics.py",  # 4.7, 2.7
    "sitl_emu/control/position.py",  # 3.6, 2.3
    "sitl_emu/control/cascade.py",  # 2.8, 2.4
    "sitl_emu/control/rate.py",  # 2.6, 1.7
    "sitl_emu/control/attitude.py",  # 2.5, 1.8
    "sitl_emu/control/mixer.py",  # 1.6, 0.6
    "sitl_emu/control/control_math.py",  # 1.5, 1.1
    "sitl_emu/control/filters.py",  # 0.9, 0.6
    "sitl_emu/control/hover.py",  # 0.8, 0.6
)
DEFAULT_MODULES = (
    *CORE_MODULES,
    # the vehicle loop and the flight stack around the controllers
    "sitl_emu/vehicle/vehicle.py",  # 6.1, 4.6
    "sitl_emu/motion_planning/smoothing.py",  # 5.2, 1.0
    "sitl_emu/commander/commander.py",  # 3.9, 3.8
    "sitl_emu/flight_tasks/core.py",  # 1.9, 0.6
    "sitl_emu/commander/failsafe.py",  # 1.8, 0.8
    "sitl_emu/vehicle/control_chain.py",  # 1.6, 1.1
    "sitl_emu/vehicle/faults.py",  # 1.4, 0.7
    "sitl_emu/flight_tasks/mode_executor.py",  # 1.4, 1.0
    "sitl_emu/vehicle/land_detector.py",  # 1.1, 0.5
    "sitl_emu/commander/arming.py",  # 0.9, 1.2
    "sitl_emu/geo.py",  # 0.5, 0.2
    "sitl_emu/commander/fault_failsafes.py",  # 0.5, 0.3
    "sitl_emu/vehicle/fence.py",  # 0.4, 0.6
    "sitl_emu/commander/battery.py",  # 0.4, 0.5
    "sitl_emu/commander/offboard.py",  # 0.3, 0.4
    "sitl_emu/navigator/geofence_monitor.py",  # 0.3, 0.1
    "sitl_emu/navigator/mission_store.py",  # 0.2, 0.6
    # the tasks that subclass flight_tasks/core.py's Task: an interpreted class cannot inherit from a compiled one
    "sitl_emu/flight_tasks/auto.py",
    "sitl_emu/flight_tasks/mission.py",
    "sitl_emu/flight_tasks/rtl.py",
    "sitl_emu/flight_tasks/rtl_mission.py",
    # the enums and the message types every module above reads each tick (0.5 %, 0.5 % of their own): a compiled module
    # reads a member of a compiled enum as a constant, but one of a pure module through Python 3.11's
    # EnumType.__getattr__ hook (~750 instructions a read)
    "sitl_emu/types.py",
    "sitl_emu/px4.py",
    # the link's per-message path: the streams and their builders, the framing, the endpoint, the node, the tick loop
    "sitl_emu/mavlink/telemetry/streams.py",  # 4.7, 3.6
    "sitl_emu/mavlink/telemetry/messages.py",  # 4.1, 3.8
    "sitl_emu/mavlink/wire/fastpack.py",  # 3.0, 2.1
    "sitl_emu/mavlink/endpoint.py",  # 2.7, 3.1
    "sitl_emu/runtime/node.py",  # 1.4, 1.3
    "sitl_emu/mavlink/telemetry/actuators.py",  # 1.0, 1.8
    "sitl_emu/mavlink/link.py",  # 1.0, 1.1
    "sitl_emu/mavlink/telemetry/sensors.py",  # 0.7, 0.5
    "sitl_emu/mavlink/telemetry/fields.py",  # the builders' float-to-integer conversions (split from messages.py)
    "sitl_emu/mavlink/context.py",  # 0.3, 0.2
    "sitl_emu/runtime/timeline.py",  # 0.0, 1.7
    "sitl_emu/mavlink/setpoints.py",  # 0.0, 0.6
    # a second profile, of the compiled build's I/O run: modules under 0.3 % of pure Python's time that hold 0.3 % or
    # more of the compiled build's (its share of each in brackets)
    "sitl_emu/motion_planning/heading.py",  # 1.8
    "sitl_emu/control/takeoff.py",  # 1.0
    "sitl_emu/navigator/geofence.py",  # 1.0
    "sitl_emu/commander/manual_control.py",  # 0.7
    "sitl_emu/commander/geofence_failsafe.py",  # 0.6
    "sitl_emu/mavlink/telemetry/health.py",  # 0.4
    "sitl_emu/navigator/setpoint.py",  # 0.3
    # a third profile (perf record of the compiled build, the core manoeuvre): pure modules whose objects the compiled
    # commander cycle reads every 8 ms, each through a Python attribute look-up or an interpreted frame (share of the
    # compiled build's time in brackets)
    "sitl_emu/commander/health_report.py",  # 5.9: HealthReporter.due every cycle, the report's inputs every 100 ms
    "sitl_emu/commander/settings.py",  # 0.7: CommanderSettings fields
    "sitl_emu/commander/mode_intention.py",  # 0.2: ModeIntention.user_intended
    # a fourth profile (the same): the parameter registry's change count, which every settings cache on the tick path
    # asks each tick or cycle, a Python attribute look-up on the interpreted registry (params/changes.py)
    "sitl_emu/params/changes.py",  # ~3
    # serve's tick path beyond Sim's: the flight log (serve writes one by default), its topics, packing and writer
    "sitl_emu/log/topics.py",
    "sitl_emu/log/ulog_writer.py",
    "sitl_emu/log/flight_log.py",
    # the links' events interface: EventsProtocol.tick runs on both links every tick (4-5 % of a 60-vehicle scale
    # run's profile, bench/scale.py, while interpreted)
    "sitl_emu/mavlink/protocols/events.py",
)

EXACT_FLOAT_FLAGS = ["-ffp-contract=off", "-fno-fast-math"]
OPT_LEVEL_ENV = "MYPYC_OPT_LEVEL"
DEFAULT_OPT_LEVEL = "1"  # measured: README, "The compiled build"
MIN_GROUPS = 4


def sha256_of(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def module_name(rel_path: str) -> str:
    return rel_path.removesuffix(".py").replace("/", ".").removesuffix(".__init__")


def _module_path(name: str) -> str | None:
    for candidate in (name.replace(".", "/") + ".py", name.replace(".", "/") + "/__init__.py"):
        if (ROOT / candidate).is_file():
            return candidate
    return None


def _imported_modules(rel_path: str) -> set[str]:
    """The sitl_emu and px4common modules one source imports (absolute imports only, as the code base uses)."""
    tree = ast.parse((ROOT / rel_path).read_text(), rel_path)
    found: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            found.add(node.module)
            found.update(f"{node.module}.{alias.name}" for alias in node.names)
    return {name for name in found if name.split(".")[0] in (PACKAGE, SHARED)}


def dependency_sources(compiled: list[str]) -> list[str]:
    """Every sitl_emu or px4common source the compiled modules import, transitively (mypyc may bake their constants
    in)."""
    seen: set[str] = set()
    todo = list(compiled)
    while todo:
        rel = todo.pop()
        if rel in seen:
            continue
        seen.add(rel)
        parts = module_name(rel).split(".")
        todo.extend(p for p in (_module_path(".".join(parts[:i])) for i in range(1, len(parts))) if p)
        todo.extend(p for p in (_module_path(name) for name in _imported_modules(rel)) if p)
    return sorted(seen - set(compiled))


def built_files() -> list[Path]:
    """Every compiled artefact under the package, whoever built it."""
    from importlib.machinery import EXTENSION_SUFFIXES

    suffixes = tuple(set(EXTENSION_SUFFIXES) | {".so", ".pyd"})
    return sorted(p for p in (ROOT / PACKAGE).rglob("*") if p.is_file() and p.name.endswith(suffixes))


def clean() -> None:
    for path in built_files():
        path.unlink()
    MANIFEST.unlink(missing_ok=True)


def opt_level(environ: Mapping[str, str] = os.environ) -> str:
    """mypyc's (and the C compiler's) optimisation level: MYPYC_OPT_LEVEL if set to 0-3, else DEFAULT_OPT_LEVEL."""
    level = environ.get(OPT_LEVEL_ENV, "").strip()
    return level if level in ("0", "1", "2", "3") else DEFAULT_OPT_LEVEL


def build_jobs() -> int:
    """C compilers to run at once: the CPUs this process may use."""
    return max(1, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1))


def group_count(jobs: int) -> int:
    """Compilation groups: one a compiler, and at least MIN_GROUPS, as gcc's time grows faster than a C file's size
    (53 modules at -O2, CPU seconds of the whole build: 2 groups 65, 4 groups 53, 8 groups 54, 16 groups 64)."""
    return max(MIN_GROUPS, jobs)


def groups(sources: list[str], count: int) -> list[tuple[list[str], str]]:
    """`sources` split into `count` compilation groups of about equal size (largest file first onto the smallest
    group), each its own C file and shared library (GROUP + index), so that the C compilers can run side by side.
    Sorted by name so that a build is the same whatever order the sources come in."""
    count = max(1, min(count, len(sources)))
    sized = sorted(sources, key=lambda rel: (-(ROOT / rel).stat().st_size, rel))
    members: list[list[str]] = [[] for _ in range(count)]
    totals = [0] * count
    for rel in sized:
        smallest = totals.index(min(totals))
        members[smallest].append(rel)
        totals[smallest] += (ROOT / rel).stat().st_size
    return [(sorted(files), f"{GROUP}{i}") for i, files in enumerate(members)]


def extensions(sources: list[str], count: int, level: str) -> list[Any]:
    """mypyc's C extensions for `sources` in `count` groups (setuptools Extension objects), with the exact-float
    flags."""
    from mypyc.build import mypycify

    built = mypycify(sources, opt_level=level, debug_level="0", separate=list(groups(sources, count)),
                     target_dir=str(BUILD_DIR))
    for ext in built:
        ext.extra_compile_args = [*ext.extra_compile_args, *EXACT_FLOAT_FLAGS]
    return built


def compile_in_place(sources: list[str]) -> None:
    """mypyc -> C -> extension modules copied next to their sources (setuptools build_ext --inplace), the C compiled
    by build_jobs() compilers at once."""
    import warnings

    from setuptools import setup

    warnings.filterwarnings("ignore", module="setuptools")  # its notes on our pyproject.toml are not for this build
    jobs = build_jobs()
    setup(
        name="sitl_emu_speedups",
        ext_modules=extensions(sources, group_count(jobs), opt_level()),
        script_args=["-q", "build_ext", "--inplace", "--force", "--parallel", str(jobs),
                     "--build-temp", str(BUILD_DIR / "temp"), "--build-lib", str(BUILD_DIR / "lib")],
    )


def manifest(sources: list[str], shared_libs: list[str], out: Path = ROOT) -> dict[str, Any]:
    """What the guard (sitl_emu/_speedups.py) checks: the sha256 of every compiled module's source and built file,
    of the shared libraries and of every source they depend on. Built files are read under `out` (the tree, or a
    wheel's build directory), sources in the tree."""
    import mypy.version

    suffix = _ext_suffix()
    compiled = {}
    for rel in sources:
        so = rel.removesuffix(".py") + suffix
        compiled[module_name(rel)] = {"py": rel, "py_sha256": sha256_of(ROOT / rel), "so": so,
                                      "so_sha256": sha256_of(out / so)}
    libs = [lib.replace(".", "/") + "__mypyc" + suffix for lib in shared_libs]
    return {
        "built_by": "tools/build_speedups.py",
        "built_at": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        "python": sys.version.split()[0],
        "ext_suffix": suffix,
        "mypy": mypy.version.__version__,
        "opt_level": opt_level(),
        "compiled": compiled,
        "shared_libs": [{"so": so, "so_sha256": sha256_of(out / so)} for so in libs],
        "depends": {rel: sha256_of(ROOT / rel) for rel in dependency_sources(sources)},
    }


def write_manifest(sources: list[str], out: Path = ROOT) -> None:
    names = [name for _, name in groups(sources, group_count(build_jobs()))]
    path = out / MANIFEST.relative_to(ROOT)
    path.write_text(json.dumps(manifest(sources, names, out), indent=1, sort_keys=True) + "\n")


def _ext_suffix() -> str:
    import sysconfig

    suffix = sysconfig.get_config_var("EXT_SUFFIX")
    assert isinstance(suffix, str)
    return suffix


def main(argv: list[str]) -> int:
    os.chdir(ROOT)
    if argv[:1] == ["--clean"]:
        clean()
        print("speedups removed: sitl_emu runs as pure Python")
        return 0
    if argv[:1] == ["--compile"]:  # the child process of _build
        compile_in_place(argv[1:])
        write_manifest(argv[1:])
        return 0
    explicit = [a for a in argv if not a.startswith("-")]
    sources = explicit or list(DEFAULT_MODULES)
    sources = [s for s in sources if not s.endswith("__init__.py")]  # a package stays pure (the guard needs it)
    missing = [s for s in sources if not (ROOT / s).is_file()]
    if missing:
        print(f"no such source: {', '.join(missing)}", file=sys.stderr)
        return 2
    for var in ("CFLAGS", "CPPFLAGS", "LDFLAGS"):
        os.environ.pop(var, None)  # keep -march=native / -ffast-math out (see the module docstring)
    started = time.monotonic()
    built = _build(sources)
    if not built and not explicit:
        print("\nmake speedups: the full set did not compile (errors above); building the controllers and the physics "
              "only. Fix the module named above to get the rest back.", file=sys.stderr)
        sources = list(CORE_MODULES)
        built = _build(sources)
    if not built:
        return 1
    print(f"speedups built in {time.monotonic() - started:.0f} s: {len(sources)} modules compiled with mypyc "
          f"({', '.join(module_name(s) for s in sources)}); `make clean-speedups` goes back to pure Python")
    return 0


def _build(sources: list[str]) -> bool:
    """Compile `sources` in a child process (a fresh mypy each time); True if every module was built."""
    clean()  # an old .so must never survive a partial rebuild
    done = subprocess.run([sys.executable, __file__, "--compile", *sources], check=False).returncode == 0
    if done and MANIFEST.is_file():
        recorded = json.loads(MANIFEST.read_text())["compiled"]
        done = all((ROOT / entry["so"]).is_file() for entry in recorded.values()) and len(recorded) == len(sources)
    if not done:
        clean()
    return bool(done)


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
