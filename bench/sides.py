"""Pure Python and the compiled build side by side in one run (issue 28): the same figure measured in child processes
that alternate between the two builds (SITL_EMU_PURE=1 turns a compiled build off, sitl_emu/_speedups.py), so that a
change in the machine's load falls on both, and their ratio is what to read.

`python -m bench.sides FIGURE` prints one figure of this process's build as JSON (the child's side).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

from sitl_emu._speedups import PURE_ENV, build_line

REPO = Path(__file__).resolve().parent.parent


def _core() -> float:
    from bench import core

    return core.core_speed()[0]


def _core_io() -> float:
    from bench import core

    return core.core_speed_with_io()


def _flight() -> float:
    from bench import serve

    reference, wall = serve.lockstep_flight()
    return reference.sim_duration_s / wall if reference.ok else float("nan")


FIGURES: dict[str, Callable[[], float]] = {"core": _core, "core_io": _core_io, "flight": _flight}


def compiled_build_here() -> bool:
    """True when this checkout (or install) has a compiled build that the guard would use."""
    environ = {k: v for k, v in os.environ.items() if k != PURE_ENV}
    return build_line(environ=environ).startswith("core: compiled")


def _environ(pure: bool) -> dict[str, str]:
    environ = {k: v for k, v in os.environ.items() if k != PURE_ENV}
    if pure:
        environ[PURE_ENV] = "1"
    environ["PYTHONPATH"] = os.pathsep.join(p for p in (str(REPO), environ.get("PYTHONPATH", "")) if p)
    return environ


def measure(figure: str, pure: bool) -> float:
    """One figure from a fresh child process running pure Python or the compiled build."""
    out = subprocess.run([sys.executable, "-m", "bench.sides", figure], cwd=REPO, env=_environ(pure),
                         capture_output=True, text=True, timeout=900, check=True)
    return float(json.loads(out.stdout.strip().splitlines()[-1]))


def side_by_side(figure: str, runs: int) -> tuple[float, float | None]:
    """(best pure, best compiled or None when there is no compiled build), runs alternating pure and compiled."""
    both = compiled_build_here()
    pure: list[float] = []
    compiled: list[float] = []
    for _ in range(runs):
        pure.append(measure(figure, pure=True))
        if both:
            compiled.append(measure(figure, pure=False))
    return max(pure), (max(compiled) if compiled else None)


def ratio_text(pure: float, compiled: float | None, unit: str) -> str:
    """'pure 310, compiled 1240 simulated s per CPU s (x4.00)', or the pure figure alone."""
    if compiled is None:
        return f"pure {pure:.0f} {unit} (no compiled build here: `make speedups`)"
    return f"pure {pure:.0f}, compiled {compiled:.0f} {unit} (compiled x{compiled / pure:.2f})"


@contextmanager
def build_for_children(pure: bool) -> Iterator[None]:
    """Processes started inside (a campaign's workers) run pure Python or the compiled build."""
    saved = os.environ.get(PURE_ENV)
    if pure:
        os.environ[PURE_ENV] = "1"
    else:
        os.environ.pop(PURE_ENV, None)
    try:
        yield
    finally:
        if saved is None:
            os.environ.pop(PURE_ENV, None)
        else:
            os.environ[PURE_ENV] = saved


if __name__ == "__main__":
    print(json.dumps(FIGURES[sys.argv[1]]()))
