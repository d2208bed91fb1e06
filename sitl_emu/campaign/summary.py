"""The summary of a campaign: pass rate, each metric's quantiles, the worst cases, and for each failed case the one
command that flies it again alone (in this process, with its traceback, writing no results file)."""

from __future__ import annotations

import json
import math
import os
import shlex
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from sitl_emu.campaign.cases import Case
from sitl_emu.campaign.scenario import Limits

__all__ = ["Summary", "rerun_command", "summarize"]

QUANTILES = (0.0, 0.5, 0.9, 0.99, 1.0)


@dataclass
class Summary:
    total: int
    passed: int
    statuses: dict[str, int]
    quantiles: dict[str, list[float]]  # metric -> values at QUANTILES (the cases with a value only)
    worst: list[dict[str, Any]]  # the failed cases first, then by the `worst_by` metric, largest first
    reruns: dict[str, str] = field(default_factory=dict)  # failed case id -> command
    left_out: dict[str, int] = field(default_factory=dict)  # metric -> cases without a value (failed or missing)

    @property
    def pass_rate(self) -> float:
        return self.passed / self.total if self.total else math.nan

    def text(self) -> str:
        lines = [f"{self.passed} of {self.total} cases passed ({100 * self.pass_rate:.1f} %)"
                 + (": " + ", ".join(f"{n} {s}" for s, n in sorted(self.statuses.items())) if self.statuses else "")]
        if self.quantiles:
            width = max(len(m) for m in self.quantiles)
            head = "  ".join(f"{_q_name(q):>10}" for q in QUANTILES)
            lines += ["", f"{'metric':<{width}}  {head}"]
            lines += [f"{m:<{width}}  " + "  ".join(f"{v:>10.4g}" for v in vals) for m, vals in self.quantiles.items()]
        if self.left_out:
            width = max(len(m) for m in self.left_out)
            lines += ["", "left out of the quantiles, without a value (a failed or missing metric):"]
            lines += [f"  {m:<{width}}  in {n} of {self.total} cases" for m, n in self.left_out.items()]
        if self.worst:
            lines += ["", "worst cases:"]
            lines += [f"  {_worst_line(row)}" for row in self.worst]
        if self.reruns:
            lines += ["", "rerun a failed case alone:"]
            lines += [f"  {case}: {cmd}" for case, cmd in self.reruns.items()]
        return "\n".join(lines)


def _q_name(q: float) -> str:
    return {0.0: "min", 1.0: "max"}.get(q, f"p{round(q * 100)}")


def _worst_line(row: Mapping[str, Any]) -> str:
    metrics = ", ".join(f"{k.removeprefix('metric.')}={v:.4g}" for k, v in row.items()
                        if k.startswith("metric.") and isinstance(v, float))
    error = f": {row['error']}" if row.get("error") else ""
    return f"{row['case']} {row['status']} (seed {row['seed']}){' ' + metrics if metrics else ''}{error}"


def summarize(rows: Sequence[Mapping[str, Any]], worst_by: str | None = None, worst_count: int = 5) -> Summary:
    """The summary of typed result rows (results.typed); `worst_by` a metric name (default: the first one)."""
    metrics = [k for k in (rows[0] if rows else {}) if k.startswith("metric.")]
    for row in rows:
        metrics += [k for k in row if k.startswith("metric.") and k not in metrics]
    statuses: dict[str, int] = {}
    for row in rows:
        if row["status"] != "passed":
            statuses[row["status"]] = statuses.get(row["status"], 0) + 1
    quantiles, left_out = {}, {}
    for metric in metrics:
        values = [v for row in rows if isinstance(v := row.get(metric), float) and math.isfinite(v)]
        name = metric.removeprefix("metric.")
        if values:
            quantiles[name] = [float(x) for x in np.quantile(values, QUANTILES)]
        if len(values) < len(rows):
            left_out[name] = len(rows) - len(values)
    key = f"metric.{worst_by}" if worst_by else (metrics[0] if metrics else None)
    ranked = sorted(rows, key=lambda r: (r["status"] == "passed", -_value(r, key), r["case"]))
    worst = [dict(r) for r in ranked[:worst_count]]
    return Summary(len(rows), len(rows) - sum(statuses.values()), statuses, quantiles, worst, left_out=left_out)


def _value(row: Mapping[str, Any], key: str | None) -> float:
    value = row.get(key) if key else None
    return value if isinstance(value, float) and math.isfinite(value) else -math.inf


def rerun_command(scenario: str, case: Case, limits: Limits, tool: str = "sitl-emu") -> str:
    """The command line that flies `case` alone, in this process, writing no results file."""
    args = [tool, "campaign", "--scenario", _short_ref(scenario), "--seed", str(case.seed)]
    for name, value in case.params.items():
        args += ["--param", f"{name}={value!r}"]
    for fault in case.faults:
        args += ["--fault", f"{fault.name}@{fault.t_s!r}"]
    for name, value in case.options.items():
        args += ["--option", f"{name}={toml_value(value)}"]
    for flag, limit in (("--sim-limit", limits.sim_s), ("--wall-limit", limits.wall_s)):
        if limit is not None:
            args += [flag, f"{limit:g}"]
    return shlex.join([*args, "--engine", "serial", "--out", "-"])


def _short_ref(ref: str) -> str:
    where, sep, name = ref.rpartition(":")
    if sep and where.endswith(".py") and Path(where).is_absolute():
        relative = os.path.relpath(where)
        if not relative.startswith(".."):
            return f"{relative}:{name}"
    return ref


def toml_value(value: Any) -> str:
    """A TOML inline value (what --option reads back)."""
    if isinstance(value, Mapping):
        return "{" + ", ".join(f"{json.dumps(str(k))} = {toml_value(v)}" for k, v in value.items()) + "}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    if isinstance(value, float):
        return repr(value) if math.isfinite(value) else ("nan" if math.isnan(value) else
                                                          ("inf" if value > 0 else "-inf"))
    return json.dumps(value)
