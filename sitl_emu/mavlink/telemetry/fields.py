"""Floats to MAVLink's integer fields, as the builders convert them: one version of each conversion, for every builder.

A diverged estimate must cost a wrong number, never a message: each conversion maps inf and NaN to 0. Rounding is
Python's round() (half to even), which the wire has always carried. Written for the compiled build (ARCHITECTURE.md,
"On the tick path"): mypyc has primitives for math.floor and int(float) but not for round() or math.isfinite, which
it calls through Python with the float boxed; the 50 Hz position streams convert up to eight fields a message.
"""

from __future__ import annotations

import math
from typing import Final

from sitl_emu.control.qmath import isfinite

INT32_MAX: Final = 0x7FFFFFFF
INT32_MIN: Final = -0x80000000
INT16_MAX: Final = 0x7FFF
INT16_MIN: Final = -0x8000


def iround(x: float) -> int:
    """round(x) (to the nearest integer, a tie to the even one) for a finite x; 0 for inf and NaN.

    On |x|: its fractional part |x| - floor(|x|) is exact (Sterbenz), so the comparisons with 0.5 are too."""
    if not isfinite(x):
        return 0
    a = abs(x)
    whole = math.floor(a)
    fraction = a - whole
    if fraction > 0.5 or (fraction == 0.5 and whole & 1):
        whole += 1
    return whole if x >= 0.0 else -whole


def itrunc(x: float) -> int:
    """int(x) (towards zero, as C converts a float) for a finite x; 0 for inf and NaN."""
    return int(x) if isfinite(x) else 0


def clamp_int(value: int, low: int, high: int) -> int:
    return high if value > high else low if value < low else value


def int32(x: float) -> int:
    """iround(x) within int32."""
    return clamp_int(iround(x), INT32_MIN, INT32_MAX)


def e7(deg: float) -> int:
    """Degrees as an int32 of 1e-7 degrees (latitude, longitude)."""
    return int32(deg * 1e7)


def mm(m: float) -> int:
    """Metres as an int32 of millimetres (altitudes)."""
    return int32(m * 1000.0)


def cm_s(m_s: float) -> int:
    """Metres per second as an int16 of centimetres per second (GLOBAL_POSITION_INT's velocities)."""
    return clamp_int(iround(m_s * 100.0), INT16_MIN, INT16_MAX)


def time_boot_ms(time_us: int) -> int:
    """A uint32 time_boot_ms field from simulated microseconds (wrapping, as PX4's hrt_absolute_time() / 1000)."""
    return (time_us // 1000) & 0xFFFFFFFF
