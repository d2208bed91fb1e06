"""PX4-named parameters: one registry, typed (INT32 or REAL32), range-checked, changeable at run time.

Which parameters exist and their defaults come from sitl_emu/params/catalog.py (PX4's list plus the `defs/*.py`
modules). As in PX4 (src/lib/parameters/parameters.cpp), every known parameter can be read and set by name, but only
the *used* ones are listed: they alone have an index, count in `len()` and go out after PARAM_REQUEST_LIST. PX4 marks
a parameter used when a module first looks it up; here the catalog says which are used at boot and `mark_used(name)`
adds one later (the mission code calls it for MIS_DIST_1WP and MIS_TKO_LAND_REQ on the first mission upload, as
PX4's navigator looks them up only then). Used parameters are listed in name order, as PX4's table.
"""

from __future__ import annotations

import bisect
import math
import struct
import zlib
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from enum import Enum
from typing import Protocol

from sitl_emu.params.changes import ChangeCount

FLT_MAX = 3.4028234663852886e38  # the largest finite float32: a REAL32 travels and is stored as float32 in PX4
INT32_MIN, INT32_MAX = -(2**31), 2**31 - 1
_F32 = struct.Struct("<f")
_I32 = struct.Struct("<i")


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
    volatile: bool = False  # PX4 @volatile: changed by the system itself, left out of the _HASH_CHECK value


def real(name: str, default: float, lo: float = -math.inf, hi: float = math.inf, unit: str = "",
         doc: str = "") -> ParamDef:
    return ParamDef(name, ParamType.REAL32, float(default), lo, hi, unit, doc)


def integer(name: str, default: int, lo: float = INT32_MIN, hi: float = INT32_MAX, unit: str = "",
            doc: str = "") -> ParamDef:
    return ParamDef(name, ParamType.INT32, int(default), lo, hi, unit, doc)


class ParamStorage(Protocol):
    """Where a registry's values are kept between runs (sitl_emu/params/store.py); the console's `param save`."""

    def save(self) -> str:
        """Write the changed values now; return where they went (raise OSError if that failed)."""
        ...


def float32(value: float) -> float:
    """`value` rounded to float32, as PX4 stores a REAL32."""
    return float(_F32.unpack(_F32.pack(value))[0])


def same_value(kind: ParamType, a: float, b: float) -> bool:
    """Equal as PX4 stores them (REAL32: the same float32)."""
    return a == b if kind is ParamType.INT32 else float32(a) == float32(b)


class ParamRegistry:
    """Values by name. `version` increases on every accepted change, so users can cache derived settings (on the tick
    path through `changes`, the same count: params/changes.py).

    `used` names the parameters listed at start (default: all of `defs`); the others are known but unlisted.
    """

    def __init__(self, defs: Iterable[ParamDef], used: Iterable[str] | None = None) -> None:
        self._defs: dict[str, ParamDef] = {}
        for d in sorted(defs, key=lambda d: d.name):
            if d.name in self._defs:
                raise ValueError(f"parameter {d.name} is defined twice")
            if len(d.name) > 16:
                raise ValueError(f"parameter name {d.name} is longer than 16 characters")
            self._defs[d.name] = d
        self._values: dict[str, float] = {d.name: d.default for d in self._defs.values()}
        self._used: list[str] = sorted(self._defs if used is None else set(used))
        unknown = [n for n in self._used if n not in self._defs]
        if unknown:
            raise ValueError(f"used parameters without a definition: {', '.join(unknown)}")
        self._index = {n: i for i, n in enumerate(self._used)}
        self.changes = ChangeCount()
        self.storage: ParamStorage | None = None  # set by whoever keeps the values between runs (`serve`)
        self._hash: tuple[int, int, int] | None = None  # (version, used count, hash)

    # --- what exists ---------------------------------------------------------------------------------------------
    @property
    def version(self) -> int:
        """How many accepted changes there were (`changes.value`)."""
        return self.changes.value

    def __contains__(self, name: object) -> bool:
        """Known by name (used or not), as PX4's param_find_no_notification finds every compiled-in parameter."""
        return name in self._defs

    def __iter__(self) -> Iterator[ParamDef]:
        """The used parameters in index order."""
        defs = self._defs
        return (defs[n] for n in self._used)

    def __len__(self) -> int:
        """How many are used (PX4's param_count_used, PARAM_VALUE.param_count)."""
        return len(self._used)

    def known(self) -> Iterator[ParamDef]:
        """Every parameter, used or not, in name order."""
        return iter(self._defs.values())

    def definition(self, name: str) -> ParamDef:
        try:
            return self._defs[name]
        except KeyError:
            raise ParamError(f"Unknown parameter {name}.") from None

    def is_used(self, name: str) -> bool:
        return name in self._index

    def mark_used(self, name: str) -> None:
        """List `name` from now on (PX4's param_find marks a parameter used on its first look-up).

        The parameter takes its place in name order, so the indices after it move up by one and `len()` grows, as in
        PX4 after a module looks up a new parameter. Call it from code that starts using a parameter PX4 also looks
        up late, e.g. the mission upload for MIS_DIST_1WP and MIS_TKO_LAND_REQ. Unknown names raise ParamError.
        """
        self.definition(name)
        if name not in self._index:
            bisect.insort(self._used, name)
            self._index = {n: i for i, n in enumerate(self._used)}

    def index_of(self, name: str) -> int:
        """The used index; -1 for a known parameter that is not used (PX4's param_get_used_index)."""
        self.definition(name)
        return self._index.get(name, -1)

    def name_at(self, index: int) -> str:
        if not 0 <= index < len(self._used):
            raise ParamError(f"No parameter at index {index}.")
        return self._used[index]

    # --- values --------------------------------------------------------------------------------------------------
    def get(self, name: str) -> float:
        """The value: an int for INT32 parameters, a float for REAL32 ones."""
        self.definition(name)
        return self._values[name]

    def __getitem__(self, name: str) -> float:
        return self.get(name)

    def set(self, name: str, value: float) -> float:
        """Set a value; raise ParamError (value kept) if unknown, read-only, not finite or out of range.

        PX4 stores NaN, infinity and out-of-range values as given; we refuse them, which is safer. A REAL32 value
        that is the same float32 as the current one changes nothing (the current value is kept as it is).
        """
        d = self.definition(name)
        if d.read_only:
            raise ParamError(f"Parameter {name} is read-only.")
        v = _checked(d, value)
        if not same_value(d.type, self._values[name], v):
            self._values[name] = v
            self.changes.value += 1
        return self._values[name]

    def reset(self, names: Iterable[str] | None = None) -> None:
        """Back to the defaults: every parameter, or those named."""
        targets = self._defs.values() if names is None else [self.definition(n) for n in names]
        changed = False
        for d in targets:
            if self._values[d.name] != d.default:
                self._values[d.name] = d.default
                changed = True
        if changed:
            self.changes.value += 1

    def values(self) -> dict[str, float]:
        """Every known parameter's value."""
        return dict(self._values)

    def is_default(self, name: str) -> bool:
        d = self.definition(name)
        return same_value(d.type, self._values[name], d.default)

    def changed(self) -> dict[str, float]:
        """The values that differ from their defaults (what PX4 saves), in name order."""
        return {n: v for n, v in self._values.items() if not same_value(self._defs[n].type, v, self._defs[n].default)}

    def hash_check(self) -> int:
        """The _HASH_CHECK value: PX4's param_hash_check() (src/lib/parameters/parameters.cpp).

        A CRC-32 step (PX4's crc32part: reflected polynomial, no inversion before or after) over each used,
        non-volatile parameter in index order: its name's bytes, then its value's four bytes as stored (int32 or
        float32, little-endian). QGroundControl computes the same over its cache to skip the download.
        """
        key = (self.version, len(self._used))
        if self._hash is not None and self._hash[:2] == key:
            return self._hash[2]
        state = 0
        for name in self._used:
            d = self._defs[name]
            if d.volatile:
                continue
            value = self._values[name]
            raw = _I32.pack(int(value)) if d.type is ParamType.INT32 else _F32.pack(value)
            state = _crc32_part(name.encode("ascii"), state)
            state = _crc32_part(raw, state)
        self._hash = (*key, state)
        return state


def _crc32_part(data: bytes, state: int) -> int:
    """PX4's crc32part(): zlib's CRC-32 without its inversion of the start value and of the result."""
    return (~zlib.crc32(data, ~state & 0xFFFFFFFF)) & 0xFFFFFFFF


def _checked(d: ParamDef, value: float) -> float:
    """`value` as `d` stores it, or ParamError: finite, an integer for INT32 (within int32), within d's range."""
    v = float(value)
    if not math.isfinite(v) or (d.type is ParamType.REAL32 and abs(v) > FLT_MAX):
        raise ParamError(f"Parameter {d.name} must be a finite number, not {value}.")
    lo, hi = d.min, d.max
    if d.type is ParamType.INT32:
        if v != int(v):
            raise ParamError(f"Parameter {d.name} is an integer; {value} is not.")
        v = int(v)
        lo, hi = max(lo, INT32_MIN), min(hi, INT32_MAX)  # whatever the definition says, it is an int32
        inside = lo <= v <= hi
    else:  # compared as float32, as the value travels: a client sending the bound 0.3 sends 0.30000001192...
        inside = float32(max(lo, -FLT_MAX)) <= float32(v) <= float32(min(hi, FLT_MAX))
    if not inside:
        raise ParamError(f"Parameter {d.name} must be within [{_fmt(lo)}, {_fmt(hi)}]; {value} is not.")
    return v


def _fmt(x: float) -> str:
    return str(x) if isinstance(x, int) else f"{x:g}"
