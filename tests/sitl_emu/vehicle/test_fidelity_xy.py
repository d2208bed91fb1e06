"""Closed-loop fidelity against real PX4 (SITL + SIH): the 10 m offboard position step of b_xy_step.csv.

Reference figures: /work/shared/reference/px4-traces/metrics.json (b_xy_step). The emulator has no estimator,
offboard link or scheduling delays, so the absolute timing (t10, settling) is slightly earlier than PX4's.
"""

from __future__ import annotations

import math

import pytest

from sitl_emu.testing.harness import Trace, hover_loop
from sitl_emu.testing.metrics import step_metrics
from sitl_emu.types import TrajectorySetpoint

PX4_XY = {"rise_time_s": 2.044, "overshoot_pct": 3.11, "settling_time_s": 6.905, "peak_speed_m_s": 5.096,
          "peak_tilt_deg": 44.21}


def _step(axis: int, target: float, seconds: float = 12.0) -> tuple[dict[str, float], Trace, float]:
    loop = hover_loop(2.5, settle_s=6.0)
    start = loop.state.pos_ned_m[axis]
    pos = [0.0, 0.0, -2.5]
    pos[axis] = target
    sp = TrajectorySetpoint(position_ned_m=tuple(pos), yaw_rad=0.0)  # type: ignore[arg-type]
    tr = loop.run(seconds, lambda t: sp)
    figures = step_metrics(tr.t_s, tr.column("pos_ned_m", axis), start, target)
    figures["peak_speed_m_s"] = max(math.sqrt(sum(c * c for c in s.vel_ned_m_s)) for s in tr.states)
    figures["peak_tilt_deg"] = math.degrees(max(tr.tilt_rad()))
    return figures, tr, start


@pytest.fixture(scope="module")
def xy_step():
    return _step(0, 10.0)


def test_metric_function_on_a_known_response():
    t = [i * 0.01 for i in range(1001)]
    y = [1.0 - math.exp(-ti) for ti in t]
    m = step_metrics(t, y, 0.0, 1.0)
    assert m["rise_time_s"] == pytest.approx(math.log(9.0), abs=0.01)
    assert m["overshoot_pct"] == 0.0
    assert m["settling_time_s"] == pytest.approx(-math.log(0.02), abs=0.01)
    assert m["final_error"] == pytest.approx(-math.exp(-10.0), abs=1e-6)


def test_xy_step_rise_overshoot_and_settling_match_px4(xy_step):
    m, _, _ = xy_step
    assert m["rise_time_s"] == pytest.approx(PX4_XY["rise_time_s"], rel=0.35)
    assert abs(m["overshoot_pct"] - PX4_XY["overshoot_pct"]) <= 10.0
    assert m["settling_time_s"] == pytest.approx(PX4_XY["settling_time_s"], rel=0.35)
    assert abs(m["final_error"]) < 0.2


def test_xy_step_peak_speed_and_tilt_match_px4(xy_step):
    m, _, _ = xy_step
    assert m["peak_speed_m_s"] == pytest.approx(PX4_XY["peak_speed_m_s"], rel=0.35)
    assert abs(m["peak_tilt_deg"] - PX4_XY["peak_tilt_deg"]) <= 12.0


def test_xy_step_keeps_altitude_and_track(xy_step):
    _, tr, _ = xy_step
    assert max(abs(z + 2.5) for z in tr.column("pos_ned_m", 2)) < 0.3  # PX4: 0.16 m
    assert max(abs(y) for y in tr.column("pos_ned_m", 1)) < 0.05  # PX4: 0.05 m


def test_vertical_5m_step_climbs_at_the_limit_without_overshoot():
    m, tr, _ = _step(2, -7.5, seconds=10.0)
    assert abs(m["final_error"]) < 0.05
    assert m["overshoot_pct"] < 5.0
    assert min(tr.column("vel_ned_m_s", 2)) > -3.05  # MPC_Z_VEL_MAX_UP
    assert 1.0 < m["rise_time_s"] < 3.0
    assert max(abs(x) for x in tr.column("pos_ned_m", 0)) < 0.05
