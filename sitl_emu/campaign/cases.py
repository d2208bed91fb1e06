"""The cases of a campaign: each one vehicle seed, PX4 parameters, timed faults and free options.

Cases come from a grid (every combination of the listed values) and/or N random draws (each case draws from its own
generator, seeded by the campaign's draw seed and the case's number, so adding cases never changes earlier ones).
Keys name what they set: `seed`, `params.NAME` (any PX4 parameter, e.g. `params.SIH_WIND_N`), `options.NAME` (handed
to `Sim(NAME=...)` when Sim takes that keyword, and always readable by the scenario as `case.options`) and `faults`
(a list of (time_s, fault) pairs, e.g. `[(12.0, "gps_off")]`: the scenario turns them into MAV_CMD_INJECT_FAILURE).
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from sitl_emu.campaign.errors import CaseError
from sitl_emu.campaign.faults import Fault, parse_fault

__all__ = ["Case", "CaseError", "FaultDraw", "check_params", "make_cases"]

DISTRIBUTIONS = ("uniform", "normal", "integers", "choice")


@dataclass(frozen=True)
class Case:
    """One flight: `id` names it in the results (c0000, c0001, ...); the rest are its inputs."""

    id: str
    seed: int = 0
    params: Mapping[str, float] = field(default_factory=dict)
    faults: tuple[Fault, ...] = ()
    options: Mapping[str, Any] = field(default_factory=dict)

    def inputs(self) -> dict[str, Any]:
        """The inputs as plain JSON values (what the key hashes and what the rerun command repeats)."""
        return {"seed": self.seed, "params": dict(sorted(self.params.items())),
                "faults": [[f.t_s, f.name] for f in self.faults], "options": dict(sorted(self.options.items()))}

    @property
    def key(self) -> str:
        """A short hash of the inputs: a rerun skips a finished case only if its inputs are the same."""
        text = json.dumps(self.inputs(), sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()[:12]


@dataclass(frozen=True)
class FaultDraw:
    """A fault each case gets with `probability`, at `at` seconds (a number or a distribution table)."""

    name: str
    at: Any
    probability: float = 1.0


def make_cases(fixed: Mapping[str, Any] | None = None, grid: Mapping[str, Sequence[Any]] | None = None,
               draws: Mapping[str, Any] | None = None, count: int = 0, draw_seed: int = 0,
               fault_draws: Sequence[FaultDraw] = ()) -> list[Case]:
    """Cases from `fixed` values (every case), a `grid` (every combination) and, when `count` > 0, `count` random
    draws per grid point from `draws` ({key: {"uniform": [lo, hi]}}, "normal": [mean, sd], "integers": [lo, hi]
    inclusive, "choice": [values]). A case's seed is `seed` if given, else its number."""
    for mapping in (fixed or {}, grid or {}, draws or {}):
        for key in mapping:
            _check_key(key)
    grid_points = _grid_points(grid or {})
    repeats = count if count > 0 else 1
    cases = []
    for index, (point, _) in enumerate(itertools.product(grid_points, range(repeats))):
        rng = np.random.default_rng([draw_seed, index])
        values = {**(fixed or {}), **point}
        if count > 0:
            values.update({key: _draw(rng, key, spec) for key, spec in (draws or {}).items()})
        cases.append(_case(index, values, [d for d in (_draw_fault(rng, f) for f in fault_draws) if d]))
    return cases


def _grid_points(grid: Mapping[str, Sequence[Any]]) -> list[dict[str, Any]]:
    for key, values in grid.items():
        if isinstance(values, (str, bytes)) or not isinstance(values, Sequence) or not values:
            raise CaseError(f"grid {key} must be a non-empty list of values, not {values!r}.")
    keys = list(grid)
    return [dict(zip(keys, combo, strict=True)) for combo in itertools.product(*(grid[k] for k in keys))]


def _check_key(key: str) -> None:
    head, dot, name = key.partition(".")
    if key in ("seed", "faults") or (dot and name and head in ("params", "options")):
        return
    raise CaseError(f"'{key}' is not a case input; use seed, faults, params.NAME or options.NAME.")


def _draw(rng: np.random.Generator, key: str, spec: Any) -> Any:
    if not isinstance(spec, Mapping) or len(spec) != 1 or next(iter(spec)) not in DISTRIBUTIONS:
        raise CaseError(f"random {key} must be one of {', '.join(DISTRIBUTIONS)} with its values, "
                        f"e.g. {{uniform = [0.0, 10.0]}}, not {spec!r}.")
    kind, args = next(iter(spec.items()))
    if not isinstance(args, Sequence) or isinstance(args, str) or not args:
        raise CaseError(f"random {key}: {kind} needs a list of values, not {args!r}.")
    if kind == "choice":
        return args[int(rng.integers(len(args)))]
    if len(args) != 2 or not all(isinstance(a, (int, float)) for a in args):
        raise CaseError(f"random {key}: {kind} needs two numbers, not {args!r}.")
    if kind == "uniform":
        return float(rng.uniform(args[0], args[1]))
    if kind == "normal":
        return float(rng.normal(args[0], args[1]))
    return int(rng.integers(int(args[0]), int(args[1]) + 1))


def _draw_fault(rng: np.random.Generator, draw: FaultDraw) -> Fault | None:
    happens = rng.uniform() < draw.probability  # drawn even at probability 1: the stream stays aligned
    at = draw.at if isinstance(draw.at, (int, float)) else _draw(rng, f"fault {draw.name} at", draw.at)
    return parse_fault(float(at), draw.name) if happens else None


def _case(index: int, values: Mapping[str, Any], drawn_faults: Iterable[Fault]) -> Case:
    params = {k.split(".", 1)[1]: _number(k, v) for k, v in values.items() if k.startswith("params.")}
    options = {k.split(".", 1)[1]: _finite(k, v, v) for k, v in values.items() if k.startswith("options.")}
    seed = values.get("seed", index)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise CaseError(f"seed must be a whole number >= 0, not {seed!r}.")
    faults = [_fault_pair(f) for f in values.get("faults", [])] + list(drawn_faults)
    return Case(f"c{index:04d}", seed, params, tuple(sorted(faults, key=lambda f: f.t_s)), options)


def _number(key: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise CaseError(f"{key} must be a finite number, not {value!r}.")
    return value


def _finite(key: str, value: Any, whole: Any) -> Any:
    """`value` (an option, or a number inside one) unless it holds nan or inf: no case flies on a number that is
    none (as params.NAME and --param refuse it)."""
    if isinstance(value, float) and not math.isfinite(value):
        shown = "" if value is whole else f" (in {whole!r})"
        raise CaseError(f"{key} must be finite, not {value!r}{shown}.")
    if isinstance(value, Mapping):
        for item in value.values():
            _finite(key, item, whole)
    elif isinstance(value, (list, tuple)):
        for item in value:
            _finite(key, item, whole)
    return value


def _fault_pair(item: Any) -> Fault:
    if isinstance(item, Fault):
        return item
    if isinstance(item, Sequence) and not isinstance(item, str) and len(item) == 2:
        return parse_fault(item[0], item[1])
    raise CaseError(f"a fault must be a pair [time_s, \"name\"] such as [12.0, \"gps_off\"], not {item!r}.")


def check_params(cases: Iterable[Case]) -> None:
    """Refuse an unknown parameter or a value out of its range before any case flies (PX4's own bounds)."""
    from sitl_emu.params import ParamError, default_registry

    registry = default_registry()
    for case in cases:
        for name, value in case.params.items():
            try:
                registry.set(name, float(value))
            except ParamError as err:
                raise CaseError(f"case {case.id}: {err}") from None
