"""Which parameters exist: PX4's list (px4_params.csv) reconciled with the definitions the emulator uses by name.

- px4_params.csv (package data, written by tools/px4_params_csv.py) is every parameter PX4 SITL (SIH quadrotor)
  lists on a fresh boot: name, MAV_PARAM_TYPE and default, in PX4's order. These are the *used* parameters; their
  order and count are PX4's, so PARAM_REQUEST_LIST returns PX4's indices.
- The `defs/<domain>.py` modules define the parameters the emulator reads by name, with a range, a unit and a
  description. A parameter in both keeps PX4's type and PX4's default unless EMULATOR_DEFAULTS lists it (a deliberate
  difference, with its reason); a definition whose default is the same float32 as PX4's keeps its own decimal form, so
  0.95 stays 0.95 (the derived controller settings do not change by a rounding).
- A definition not in PX4's list is known but not used (not listed), as a parameter PX4 compiles in but no module
  looks up: readable and settable by name, index -1. MIS_DIST_1WP and MIS_TKO_LAND_REQ are such until the first
  mission upload marks them used (ParamRegistry.mark_used).
- px4_param_meta.csv (package data, ranges and units written by tools/px4_param_meta.py from PX4's parameter
  reference) gives every listed parameter PX4's minimum, maximum and unit where PX4 states them, and a one-line
  description in our own words. A parameter only in PX4's list takes its range and unit from there (a bound PX4 does
  not state is the type's: an int32, or a finite float32). A defined one keeps the range and unit of its definition,
  which must agree with PX4's where PX4 states them (tests/sitl_emu/params/test_meta.py); every listed parameter's
  description is the data file's.
- The registry refuses a value outside the range (registry.py), as it does for the defined parameters; PX4 itself
  stores any value a client sends. No PX4 SITL default lies outside PX4's stated range (tested), so a client that
  keeps to the ranges PX4 publishes is never refused.
"""

from __future__ import annotations

import csv
import dataclasses
import importlib
import io
from functools import lru_cache
from importlib import resources

from sitl_emu.params.registry import FLT_MAX, INT32_MAX, INT32_MIN, ParamDef, ParamType, same_value

DATA_FILE = "px4_params.csv"
META_FILE = "px4_param_meta.csv"
DOMAINS = ("sih", "mpc", "mc", "commander", "navigator", "system", "faults")  # one defs/<domain>.py module each

# PX4's @volatile parameters among the listed ones (the system changes them itself; _HASH_CHECK leaves them out):
# src/modules/commander/commander_params.c COM_FLIGHT_UUID, src/modules/land_detector/land_detector_params.c
# LND_FLIGHT_T_HI/LO. PX4 main may mark more (its hash of the recorded defaults, 0x88583ebe, is not reproduced by
# leaving out these three), so our _HASH_CHECK value differs from PX4's for the same values; clients only compare it
# with the hash of what they cached from the same vehicle, which stays consistent.
VOLATILE = frozenset({"COM_FLIGHT_UUID", "LND_FLIGHT_T_HI", "LND_FLIGHT_T_LO"})

# Defaults where the emulator deliberately differs from PX4 SITL, and why.
EMULATOR_DEFAULTS: dict[str, str] = {}


@dataclasses.dataclass(frozen=True)
class Meta:
    """PX4's stated range and unit of a parameter (None: not stated) and our one-line description."""

    min: float | None
    max: float | None
    unit: str
    doc: str


@dataclasses.dataclass(frozen=True)
class Catalog:
    defs: tuple[ParamDef, ...]  # every known parameter
    used: tuple[str, ...]  # the listed ones, in PX4's order
    px4_defaults: dict[str, float]  # PX4's default of each listed parameter


def emulator_definitions() -> list[ParamDef]:
    """The `defs/*.py` definitions, in domain order."""
    defs: list[ParamDef] = []
    for domain in DOMAINS:
        module = importlib.import_module(f"sitl_emu.params.defs.{domain}")
        defs.extend(module.PARAMS)
    return defs


def read_px4_rows(text: str) -> list[tuple[str, ParamType, float]]:
    """(name, type, default) from the data file's text: '#' comment lines, a header line, then one line each."""
    lines = [line for line in text.splitlines() if line and not line.startswith("#")]
    rows = []
    for name, kind, default in csv.reader(io.StringIO("\n".join(lines[1:]))):
        ptype = ParamType(kind)
        rows.append((name, ptype, int(default) if ptype is ParamType.INT32 else float(default)))
    return rows


def read_meta_rows(text: str) -> dict[str, Meta]:
    """name -> Meta from the metadata file's text ('#' comment lines, a header line, then one line each)."""
    lines = [line for line in text.splitlines() if line and not line.startswith("#")]
    return {row["name"]: Meta(_bound(row["min"]), _bound(row["max"]), row["unit"], row["description"])
            for row in csv.DictReader(io.StringIO("\n".join(lines)))}


def _bound(cell: str) -> float | None:
    return float(cell) if cell else None


def px4_metadata() -> dict[str, Meta]:
    """The packaged metadata of PX4's listed parameters."""
    return read_meta_rows(resources.files("sitl_emu.params").joinpath(META_FILE).read_text(encoding="utf-8"))


@lru_cache(maxsize=1)
def px4_catalog() -> Catalog:
    """PX4's list and the emulator's definitions reconciled (built once per process; the ParamDefs are immutable)."""
    text = resources.files("sitl_emu.params").joinpath(DATA_FILE).read_text(encoding="ascii")
    rows = read_px4_rows(text)
    meta = px4_metadata()
    own = {d.name: d for d in emulator_definitions()}
    defs = [_reconcile(own.pop(name, None), meta.get(name), name, ptype, default) for name, ptype, default in rows]
    return Catalog(tuple(defs) + tuple(own.values()), tuple(name for name, _, _ in rows),
                   {name: default for name, _, default in rows})


def _reconcile(own: ParamDef | None, meta: Meta | None, name: str, ptype: ParamType, px4_default: float) -> ParamDef:
    meta = meta or Meta(None, None, "", "")
    if own is None:
        lo, hi = (INT32_MIN, INT32_MAX) if ptype is ParamType.INT32 else (-FLT_MAX, FLT_MAX)
        lo, hi = _typed(ptype, meta.min, lo), _typed(ptype, meta.max, hi)
        return ParamDef(name, ptype, px4_default, lo, hi, meta.unit, meta.doc, volatile=name in VOLATILE)
    if own.type is not ptype:
        raise ValueError(f"{name} is {own.type.value} in defs/*.py but {ptype.value} in PX4's list")
    keep_own = same_value(ptype, own.default, px4_default) or name in EMULATOR_DEFAULTS
    return dataclasses.replace(own, default=own.default if keep_own else px4_default, unit=own.unit or meta.unit,
                               doc=meta.doc or own.doc, volatile=name in VOLATILE)


def _typed(ptype: ParamType, bound: float | None, fallback: float) -> float:
    """A stated bound as the parameter's type keeps it (an int for INT32), or the type's own limit."""
    if bound is None:
        return fallback
    return int(bound) if ptype is ParamType.INT32 else bound
