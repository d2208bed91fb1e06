"""PX4-named parameters: one registry, typed (INT32 or REAL32), range-checked, changeable at run time.

Definitions live in the `defs_*.py` modules of this package, one per domain; `default_registry()` gathers them.
PX4 lists parameters in name order (param_find index), so the registry does too.
"""

from __future__ import annotations

import math
import zlib
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from enum import Enum


class ParamType(Enum):
    INT32 = "INT32"
    REAL32 = "REAL32"


class ParamError(ValueError):
    """A refused get or set; str(err) is one sentence for the user."""


@dataclass(frozen=True, slots=True)
class ParamDef:
    name: str
    type: ParamType
    default: float
    min: float = -math.inf
    max: float = math.inf
    unit: str = ""
    doc: str = ""
    read_only: bool = False


def real(name: str, default: float, lo: float = -math.inf, hi: float = math.inf, unit: str = "",
         doc: str = "") -> ParamDef:
    return ParamDef(name, ParamType.REAL32, float(default), lo, hi, unit, doc)


def integer(name: str, default: int, lo: float = -2**31, hi: float = 2**31 - 1, unit: str = "",
            doc: str = "") -> ParamDef:
    return ParamDef(name, ParamType.INT32, int(default), lo, hi, unit, doc)


class ParamRegistry:
    """Values by name. `version` increases on every accepted set, so users can cache derived settings."""

    def __init__(self, defs: Iterable[ParamDef]) -> None:
        ordered = sorted(defs, key=lambda d: d.name)
        self._defs: dict[str, ParamDef] = {}
        for d in ordered:
            if d.name in self._defs:
                raise ValueError(f"parameter {d.name} is defined twice")
            if len(d.name) > 16:
                raise ValueError(f"parameter name {d.name} is longer than 16 characters")
            self._defs[d.name] = d
        self._names = list(self._defs)
        self._index = {n: i for i, n in enumerate(self._names)}
        self._values: dict[str, float] = {d.name: d.default for d in ordered}
        self.version = 0

    def __contains__(self, name: object) -> bool:
        return name in self._defs

    def __iter__(self) -> Iterator[ParamDef]:
        return iter(self._defs.values())

    def __len__(self) -> int:
        return len(self._defs)

    def definition(self, name: str) -> ParamDef:
        try:
            return self._defs[name]
        except KeyError:
            raise ParamError(f"Unknown parameter {name}.") from None

    def get(self, name: str) -> float:
        """The value: an int for INT32 parameters, a float for REAL32 ones."""
        self.definition(name)
        return self._values[name]

    def __getitem__(self, name: str) -> float:
        return self.get(name)

    def index_of(self, name: str) -> int:
        self.definition(name)
        return self._index[name]

    def name_at(self, index: int) -> str:
        if not 0 <= index < len(self._names):
            raise ParamError(f"No parameter at index {index}.")
        return self._names[index]

    def set(self, name: str, value: float) -> float:
        """Set a value; raise ParamError (value kept) if unknown, read-only, not finite or out of range.

        PX4 stores NaN, infinity and out-of-range values as given; we refuse them, which is safer.
        """
        d = self.definition(name)
        if d.read_only:
            raise ParamError(f"Parameter {name} is read-only.")
        v = float(value)
        if not math.isfinite(v):
            raise ParamError(f"Parameter {name} must be a finite number, not {value}.")
        if d.type is ParamType.INT32:
            if v != int(v):
                raise ParamError(f"Parameter {name} is an integer; {value} is not.")
            v = int(v)
        if not d.min <= v <= d.max:
            raise ParamError(f"Parameter {name} must be within [{_fmt(d.min)}, {_fmt(d.max)}]; {value} is not.")
        if self._values[name] != v:
            self._values[name] = v
            self.version += 1
        return v

    def reset(self) -> None:
        for d in self._defs.values():
            self._values[d.name] = d.default
        self.version += 1

    def values(self) -> dict[str, float]:
        return dict(self._values)

    def hash(self) -> int:
        """A uint32 over names, types and values, like PX4's param_hash_check (value of _HASH_CHECK)."""
        crc = 0
        for name in self._names:
            crc = zlib.crc32(f"{name}={self._values[name]!r};".encode(), crc)
        return crc & 0xFFFFFFFF


def _fmt(x: float) -> str:
    return f"{x:g}"
