"""Step-response figures, computed the way the reference traces' metrics.json reports them.

rise time 10-90 %, overshoot in percent of the step, 2 % settling time (last time the response is outside a band of
2 % of the step around the target), final error (last value minus target, signed along the step direction).
"""

from __future__ import annotations

import math
from collections.abc import Sequence


def step_metrics(times_s: Sequence[float], values: Sequence[float], start: float, target: float,
                 band: float = 0.02) -> dict[str, float]:
    """Figures of the response `values` (at `times_s`, step at t=0) moving from `start` to `target`."""
    span = target - start
    if span == 0.0 or not values:
        raise ValueError("step_metrics needs a non-zero step and at least one sample")
    frac = [(v - start) / span for v in values]  # 0 at start, 1 at target, whatever the direction
    t10 = _first_crossing(times_s, frac, 0.1)
    t90 = _first_crossing(times_s, frac, 0.9)
    peak = max(frac)
    outside = [t for t, f in zip(times_s, frac, strict=True) if abs(f - 1.0) > band]
    settling = outside[-1] if outside else times_s[0]
    if outside and outside[-1] == times_s[-1]:
        settling = math.nan  # never settled within the record
    return {
        "t10_s": t10,
        "rise_time_s": t90 - t10,
        "overshoot_pct": max(0.0, (peak - 1.0) * 100.0),
        "settling_time_s": settling,
        "final_error": (frac[-1] - 1.0) * abs(span),
    }


def _first_crossing(times_s: Sequence[float], frac: Sequence[float], level: float) -> float:
    for i, f in enumerate(frac):
        if f >= level:
            if i == 0:
                return times_s[0]
            f0, t0 = frac[i - 1], times_s[i - 1]
            return t0 + (level - f0) / (f - f0) * (times_s[i] - t0)
    return math.nan
