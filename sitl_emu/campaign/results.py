"""The results table: one CSV row per case, appended as each case finishes, and a Parquet copy when pyarrow is there.

Columns, in this order: `case` (c0000...), `key` (a hash of the inputs: a rerun skips a case only if it matches),
`seed`, `faults` (`name@time_s` joined by `;`), `param.NAME` and `option.NAME` (the inputs), `passed` (true/false),
`status` (passed, failed: the scenario's verdict; error: it raised; sim_limit, timeout: the simulated or wall-time
limit; crashed: the worker died), `error` (one line), then `metric.NAME` (the scenario's numbers; empty where a case
measured none: it failed early, returned None or nan, or never named it), `sim_s` and `wall_s`. Only `wall_s`
differs between two runs of the same cases.

A row goes to disk (flushed) when its case finishes, so a campaign that dies loses no finished case; a metric column
first seen late rewrites the file once with the wider header.
"""

from __future__ import annotations

import csv
import json
import math
import os
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from sitl_emu.campaign.cases import Case
from sitl_emu.campaign.errors import CampaignError

__all__ = ["ResultsFile", "case_columns", "input_columns", "read_rows", "typed", "write_parquet"]

HEAD = ("case", "key", "seed", "faults")
VERDICT = ("passed", "status", "error")
TAIL = ("sim_s", "wall_s")
NUMERIC_PREFIXES = ("param.", "metric.")


def input_columns(cases: Iterable[Case]) -> list[str]:
    params = sorted({f"param.{name}" for case in cases for name in case.params})
    options = sorted({f"option.{name}" for case in cases for name in case.options})
    return [*HEAD, *params, *options, *VERDICT]


def case_columns(case: Case) -> dict[str, Any]:
    return {"case": case.id, "key": case.key, "seed": case.seed,
            "faults": ";".join(f"{f.name}@{f.t_s:g}" for f in case.faults),
            **{f"param.{k}": v for k, v in case.params.items()}, **{f"option.{k}": v for k, v in case.options.items()}}


def cell(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value) if math.isfinite(value) else ("nan" if math.isnan(value) else repr(value))
    if isinstance(value, (int, str)):
        return str(value)
    return json.dumps(value, sort_keys=True)


def read_rows(path: Path) -> tuple[list[str], list[dict[str, str]]]:
    """The header and the rows of a results file (empty when it does not exist)."""
    if not path.exists():
        return [], []
    try:
        with path.open(newline="") as f:
            reader = csv.DictReader(f)
            rows = [dict(r) for r in reader]
            header = list(reader.fieldnames or [])
    except (OSError, csv.Error, UnicodeDecodeError) as err:
        raise CampaignError(f"cannot read the results file {path}: {err}.") from None
    if rows and ("case" not in header or "key" not in header):
        raise CampaignError(f"{path} is not a campaign results file (no case and key columns); choose another --out.")
    return header, rows


class ResultsFile:
    """The CSV at `path`: the rows already there (kept) and the rows added as cases finish (None: in memory only)."""

    def __init__(self, path: Path | None, columns: Sequence[str]) -> None:
        self.path = path
        if path is not None and not path.parent.exists():
            raise CampaignError(f"cannot write the results file {path}: the folder {path.parent} does not exist; "
                                "create it or choose another --out.")
        header, self.rows = read_rows(path) if path is not None else ([], [])
        self.columns = list(columns) + [c for c in header if c not in columns and c not in TAIL] + list(TAIL)
        if path is not None and header != self.columns:
            self._rewrite()

    def finished(self, cases: Iterable[Case]) -> set[str]:
        """The ids of `cases` with a row already; CampaignError if a row holds other inputs under the same id."""
        keys = {row.get("case", ""): row.get("key", "") for row in self.rows}
        done = set()
        for case in cases:
            if case.id in keys:
                if keys[case.id] != case.key:
                    raise CampaignError(f"{self.path} already holds case {case.id} with other inputs; write to "
                                        "another --out, or delete that file to start again.")
                done.add(case.id)
        return done

    def add(self, row: Mapping[str, Any]) -> None:
        text = {k: cell(v) for k, v in row.items()}
        self.rows.append(text)
        new = [k for k in text if k not in self.columns]
        if self.path is None:
            self.columns[-len(TAIL):-len(TAIL)] = new
            return
        if new:
            self.columns[-len(TAIL):-len(TAIL)] = new
            self._rewrite()
            return
        try:
            with self.path.open("a", newline="") as f:
                csv.DictWriter(f, self.columns, restval="").writerow(text)
                f.flush()
        except OSError as err:
            raise self._cannot_write(err) from None

    def _rewrite(self) -> None:
        if self.path is None:
            return
        tmp = self.path.with_name(self.path.name + ".tmp")
        try:
            with tmp.open("w", newline="") as f:
                writer = csv.DictWriter(f, self.columns, restval="")
                writer.writeheader()
                writer.writerows(self.rows)
            os.replace(tmp, self.path)
        except OSError as err:
            raise self._cannot_write(err) from None

    def _cannot_write(self, err: OSError) -> CampaignError:
        return CampaignError(f"cannot write the results file {self.path}: {err.strerror or err}; choose another --out.")


def typed(row: Mapping[str, str]) -> dict[str, Any]:
    """A CSV row with numbers as numbers and `passed` as a bool (for the summary and Parquet)."""
    out: dict[str, Any] = {}
    for key, text in row.items():
        if key == "passed":
            out[key] = text == "true"
        elif key == "seed":
            out[key] = int(text) if text.isdigit() else None
        elif key.startswith(NUMERIC_PREFIXES) or key in TAIL:
            out[key] = _number(text)
        else:
            out[key] = text
    return out


def _number(text: str) -> float | None:
    try:
        return float(text)
    except ValueError:
        return None


def write_parquet(csv_path: Path) -> Path | None:
    """The same table as `<stem>.parquet` beside the CSV, typed; None when pyarrow is not installed."""
    try:
        import pyarrow as pa  # type: ignore[import-untyped, unused-ignore]
        import pyarrow.parquet as pq  # type: ignore[import-untyped, unused-ignore]
    except ImportError:
        return None
    header, rows = read_rows(csv_path)
    table = pa.Table.from_pylist([typed(r) for r in rows], schema=None) if rows else pa.table({c: [] for c in header})
    target = csv_path.with_suffix(".parquet")
    pq.write_table(table, target)
    return target
