"""`make speedups`: compile the hot modules of the vehicle core in place with mypyc (opt-in, never by default).

usage: .venv/bin/python tools/build_speedups.py [--clean] [MODULE.py ...]

The compiled extension modules are written next to their sources (sitl_emu/.../*.so), plus one shared library
(sitl_emu/_speedups_native__mypyc*.so) and a manifest (sitl_emu/_speedups_manifest.json) that records the sha256 of
every source the build read. At import time sitl_emu/_speedups.py compares the manifest with the sources and falls
back to the pure-Python modules, with one warning, when anything changed since the build.

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
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = "sitl_emu"
SHARED = "px4common"  # the package sitl_emu shares with joyfly: compiled modules import it, so the manifest tracks it
GROUP = "sitl_emu._speedups_native"  # the shared library: sitl_emu/_speedups_native__mypyc<EXT_SUFFIX>
MANIFEST = ROOT / PACKAGE / "_speedups_manifest.json"
BUILD_DIR = Path("build") / "mypyc"

# The vehicle core's hot path, measured with `python -m bench --only core` (README, "make speedups"). CORE_MODULES
# are the controllers and the physics; the flight stack and the vehicle loop around them about double the gain again.
CORE_MODULES = (
    "sitl_emu/physics.py",
    "sitl_emu/control/attitude.py",
    "sitl_emu/control/cascade.py",
    "sitl_emu/control/control_math.py",
    "sitl_emu/control/filters.py",
    "sitl_emu/control/hover.py",
    "sitl_emu/control/mixer.py",
    "sitl_emu/control/position.py",
    "sitl_emu/control/qmath.py",
    "sitl_emu/control/rate.py",
    "sitl_emu/control/takeoff.py",
)
DEFAULT_MODULES = (
    *CORE_MODULES,
    "sitl_emu/commander/arming.py",
    "sitl_emu/commander/commander.py",
    "sitl_emu/commander/commands.py",
    "sitl_emu/commander/failsafe.py",
    "sitl_emu/vehicle/land_detector.py",
    "sitl_emu/commander/manual_control.py",
    "sitl_emu/flight_tasks/mode_executor.py",
    "sitl_emu/commander/mode_intention.py",
    "sitl_emu/commander/offboard.py",
    "sitl_emu/motion_planning/smoothing.py",
    "sitl_emu/flight_tasks/stabilized.py",
    "sitl_emu/commander/stick_gestures.py",
    "sitl_emu/flight_tasks/sticks.py",
    "sitl_emu/flight_tasks/auto.py",
    "sitl_emu/flight_tasks/core.py",
    "sitl_emu/navigator/setpoint.py",
    "sitl_emu/flight_tasks/manual.py",
    "sitl_emu/flight_tasks/mission.py",
    "sitl_emu/flight_tasks/orbit.py",
    "sitl_emu/flight_tasks/rtl.py",
    "sitl_emu/vehicle/vehicle.py",
    "sitl_emu/vehicle/control_chain.py",
    "sitl_emu/geo.py",
    # the features' per-cycle work: faults, battery, geofence and the stored plans
    "sitl_emu/vehicle/faults.py",
    "sitl_emu/vehicle/fence.py",
    "sitl_emu/commander/battery.py",
    "sitl_emu/commander/failure_injection.py",
    "sitl_emu/commander/fault_failsafes.py",
    "sitl_emu/navigator/geofence.py",
    "sitl_emu/commander/geofence_failsafe.py",
    "sitl_emu/navigator/geofence_monitor.py",
    "sitl_emu/motion_planning/heading.py",
    "sitl_emu/navigator/mission_store.py",
    # what those modules read every tick: the enums and the message types (a compiled module reads a member of an enum
    # compiled with it as a constant, but one of a pure module through Python 3.11's EnumType.__getattr__ hook, ~750
    # instructions a read), the commander's settings, the navigator's other tasks, the wind and the estimate noise
    "sitl_emu/types.py",
    "sitl_emu/px4.py",
    "sitl_emu/commander/settings.py",
    "sitl_emu/navigator/commands.py",
    "sitl_emu/navigator/mission.py",
    "sitl_emu/navigator/mission_items.py",
    "sitl_emu/navigator/rally.py",
    "sitl_emu/flight_tasks/follow.py",
    "sitl_emu/flight_tasks/follow_estimator.py",
    "sitl_emu/disturbance/wind.py",
    "sitl_emu/disturbance/estimate.py",
    # the link's per-message path, most of `serve`'s own cost: the streams and their builders, the framing, the
    # endpoint, the socket and the node
    "sitl_emu/mavlink/telemetry/streams.py",
    "sitl_emu/mavlink/telemetry/messages.py",
    "sitl_emu/mavlink/telemetry/actuators.py",
    "sitl_emu/mavlink/telemetry/health.py",
    "sitl_emu/mavlink/telemetry/sensors.py",
    "sitl_emu/mavlink/endpoint.py",
    "sitl_emu/mavlink/link.py",
    "sitl_emu/mavlink/wire/fastpack.py",
    "sitl_emu/mavlink/context.py",
    "sitl_emu/runtime/node.py",
    # the flight log's per-tick path: the topics, their packing, the writer
    "sitl_emu/log/topics.py",
    "sitl_emu/log/ulog_writer.py",
    "sitl_emu/log/flight_log.py",
)

EXACT_FLOAT_FLAGS = ["-ffp-contract=off", "-fno-fast-math"]


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


def compile_in_place(sources: list[str]) -> None:
    """mypyc -> C -> extension modules copied next to their sources (setuptools build_ext --inplace)."""
    import warnings

    from mypyc.build import mypycify
    from setuptools import setup

    warnings.filterwarnings("ignore", module="setuptools")  # its notes on our pyproject.toml are not for this build

    extensions = mypycify(sources, opt_level="3", debug_level="0", group_name=GROUP, target_dir=str(BUILD_DIR))
    for ext in extensions:
        ext.extra_compile_args = [*ext.extra_compile_args, *EXACT_FLOAT_FLAGS]
    setup(
        name="sitl_emu_speedups",
        ext_modules=extensions,
        script_args=["-q", "build_ext", "--inplace", "--force", "--build-temp", str(BUILD_DIR / "temp"),
                     "--build-lib", str(BUILD_DIR / "lib")],
    )


def write_manifest(sources: list[str]) -> None:
    import mypy.version

    suffix = _ext_suffix()
    compiled = {}
    for rel in sources:
        so = Path(rel.removesuffix(".py") + suffix)
        compiled[module_name(rel)] = {"py": rel, "py_sha256": sha256_of(ROOT / rel), "so": str(so),
                                      "so_sha256": sha256_of(ROOT / so)}
    shared = Path(GROUP.replace(".", "/") + "__mypyc" + suffix)
    manifest = {
        "built_by": "make speedups (tools/build_speedups.py)",
        "built_at": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        "python": sys.version.split()[0],
        "ext_suffix": suffix,
        "mypy": mypy.version.__version__,
        "compiled": compiled,
        "shared_lib": {"so": str(shared), "so_sha256": sha256_of(ROOT / shared)},
        "depends": {rel: sha256_of(ROOT / rel) for rel in dependency_sources(sources)},
    }
    MANIFEST.write_text(json.dumps(manifest, indent=1, sort_keys=True) + "\n")


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
