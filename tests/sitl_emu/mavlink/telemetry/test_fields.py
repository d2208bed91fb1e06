"""The builders' float-to-integer conversions (telemetry/fields.py) give what Python's round() and int() give, within
the field's range, and 0 for inf and NaN."""

from __future__ import annotations

import math
import random

from sitl_emu.control.qmath import degrees
from sitl_emu.mavlink.telemetry import fields

NAN = math.nan
EDGES = [0.0, -0.0, 0.5, -0.5, 1.5, -1.5, 2.5, -2.5, 0.49999999999999994, -0.49999999999999994, 1e-300, -1e-300,
         2**52 - 0.5, 2**52 + 1.0, 2**53, -(2**52) + 0.5, 4503599627370495.5, 2**31 - 0.5, 2**31 - 0.6, -(2**31) - 0.5,
         32767.5, -32768.5, 1e300, -1e300, 5e-324]


def _samples() -> list[float]:
    rng = random.Random(3)
    halves = [n + 0.5 for n in range(-40, 40)]
    near = [math.nextafter(h, d) for h in halves for d in (-math.inf, math.inf)]
    scaled = [rng.uniform(-1.0, 1.0) * 10.0 ** rng.randrange(-3, 16) for _ in range(5000)]
    return EDGES + halves + near + scaled


def _int32_ref(x: float) -> int:
    return max(min(round(x) if math.isfinite(x) else 0, 2**31 - 1), -(2**31))


def test_iround_is_pythons_round_half_to_even():
    for x in _samples():
        assert fields.iround(x) == round(x), x
        assert fields.itrunc(x) == int(x), x
    for x in (NAN, math.inf, -math.inf):
        assert fields.iround(x) == 0 and fields.itrunc(x) == 0


def test_integer_fields_saturate_and_send_zero_for_non_finite_values():
    for x in [*_samples(), NAN, math.inf, -math.inf]:
        assert fields.int32(x) == _int32_ref(x), x
        assert fields.cm_s(x / 100.0) == max(min(_int32_ref(x / 100.0 * 100.0), 32767), -32768), x
        assert fields.e7(x / 1e7) == _int32_ref(x / 1e7 * 1e7), x
        assert fields.mm(x / 1000.0) == _int32_ref(x / 1000.0 * 1000.0), x


def test_degrees_and_time_boot_ms_are_the_usual_ones():
    for x in _samples():
        assert degrees(x) == math.degrees(x)  # the builders' degrees: control/qmath.py's
    assert fields.time_boot_ms(2**32 * 1000 + 5_999) == 5
