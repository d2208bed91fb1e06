"""The emulated vehicle takes off and lands like real PX4 SITL (reference traces a_takeoff and f_land).

The real figures come from /work/shared/reference/px4-traces/metrics.json (copied below so the test runs without
that folder): times within +-35 %, peak climb/descent rates within +-35 %, final altitude 2.5 +- 0.1 m.
"""

from __future__ import annotations

import math
import statistics
from dataclasses import dataclass

import pytest

from sitl_emu.px4 import LandedState, MavCmd, NavState
from sitl_emu.testing.metrics import step_metrics
from sitl_emu.types import VehicleCommand
from sitl_emu.vehicle.vehicle import Vehicle

NAN7 = (math.nan,) * 7
ARM = VehicleCommand(MavCmd.COMPONENT_ARM_DISARM, (1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0))
TAKEOFF = VehicleCommand(MavCmd.NAV_TAKEOFF, NAN7)
LAND = VehicleCommand(MavCmd.NAV_LAND, NAN7)

PX4_TAKEOFF = {"liftoff_delay_s": 4.305, "peak_climb_rate_ms": 0.902, "t_mode_hold_s": 7.07, "t10_s": 4.577,
               "rise_time_s": 3.792, "settling_time_s": 10.737, "final_alt_m": 2.471}
PX4_LAND = {"time_to_landed_state_s": 7.78, "time_to_disarm_s": 9.8, "peak_descent_rate_ms": 0.696,
            "median_descent_rate_ms": 0.509}
TOL = 0.35


@dataclass
class Sample:
    t_s: float
    up_m: float
    climb_m_s: float
    nav_state: NavState
    landed: LandedState
    armed: bool


def record(vehicle: Vehicle, seconds: float) -> list[Sample]:
    t0 = vehicle.time_us
    out = []
    while vehicle.time_us < t0 + seconds * 1e6:
        vehicle.step()
        s = vehicle.snapshot()
        out.append(Sample((vehicle.time_us - t0) / 1e6, -s.pos_ned_m[2], -s.vel_ned_m_s[2], s.nav_state,
                          s.landed_state, s.armed))
    return out


@pytest.fixture(scope="module")
def flight() -> tuple[list[Sample], list[Sample], list[str]]:
    vehicle = Vehicle()
    vehicle.run_until(3_000_000)  # estimator ready (ready_delay_s 2 s)
    seq = vehicle.last_event_seq
    assert vehicle.handle_command(ARM).result == 0
    assert vehicle.handle_command(TAKEOFF).result == 0
    takeoff = record(vehicle, 12.0)  # as long as the PX4 recording
    record(vehicle, 4.0)  # settle in Hold
    assert vehicle.handle_command(LAND).result == 0
    land = record(vehicle, 14.0)
    texts = [e.text for e in vehicle.events_after(seq)]
    return takeoff, land, texts


def first(samples: list[Sample], cond) -> float:
    return next(s.t_s for s in samples if cond(s))


def within(value: float, reference: float, tol: float = TOL) -> bool:
    return abs(value - reference) <= tol * abs(reference)


def test_takeoff_timing_and_climb_rate_match_px4(flight):
    takeoff, _land, texts = flight
    assert "Using default takeoff altitude: 2.5 m" in texts
    liftoff = first(takeoff, lambda s: s.up_m > 0.1)
    hold = first(takeoff, lambda s: s.nav_state == NavState.AUTO_LOITER)
    peak = max(s.climb_m_s for s in takeoff)
    assert within(liftoff, PX4_TAKEOFF["liftoff_delay_s"]), liftoff
    assert within(hold, PX4_TAKEOFF["t_mode_hold_s"]), hold
    assert within(peak, PX4_TAKEOFF["peak_climb_rate_ms"]), peak
    assert peak <= 1.5 + 0.05  # never above MPC_TKO_SPEED


def test_takeoff_step_shape_matches_px4(flight):
    takeoff, _land, _texts = flight
    m = step_metrics([s.t_s for s in takeoff], [s.up_m for s in takeoff], 0.0, 2.5)
    assert within(m["t10_s"], PX4_TAKEOFF["t10_s"]), m
    assert within(m["rise_time_s"], PX4_TAKEOFF["rise_time_s"]), m
    assert within(m["settling_time_s"], PX4_TAKEOFF["settling_time_s"]), m
    assert m["overshoot_pct"] < 2.0
    assert takeoff[-1].up_m == pytest.approx(2.5, abs=0.1)


def test_landing_timing_and_descent_rate_match_px4(flight):
    _takeoff, land, texts = flight
    landed = first(land, lambda s: s.landed == LandedState.ON_GROUND)
    disarmed = first(land, lambda s: not s.armed)
    descending = [-s.climb_m_s for s in land if -s.climb_m_s > 0.05]
    assert within(landed, PX4_LAND["time_to_landed_state_s"]), landed
    assert within(disarmed, PX4_LAND["time_to_disarm_s"]), disarmed
    assert disarmed - landed == pytest.approx(2.0, abs=0.1)  # COM_DISARM_LAND
    assert within(max(descending), PX4_LAND["peak_descent_rate_ms"]), max(descending)
    assert within(statistics.median(descending), PX4_LAND["median_descent_rate_ms"]), statistics.median(descending)
    assert land[0].landed == LandedState.LANDING or land[5].landed == LandedState.LANDING
    assert "Landing detected" in texts and "Disarmed by landing" in texts
