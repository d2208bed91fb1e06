"""The multicopter land detector's stages and timings (PX4 MulticopterLandDetector, reference section 5.4)."""

from __future__ import annotations

import itertools
import math

import pytest

from sitl_emu.params import default_registry
from sitl_emu.vehicle.land_detector import LandDetector, LandDetectorInput, LandDetectorState

STEP_US = 4000
HOVER = 0.5  # thresholds with MPC_THR_MIN 0.12: ground contact <= 0.348, maybe landed <= 0.158


def inp(t_us: int, *, armed: bool = True, vz: float = 0.0, vxy: float = 0.0, thrust: float = 0.12,
        rates: float = 0.0, force: float = 9.81, sp_vz: float = 0.5, descent: bool = True) -> LandDetectorInput:
    return LandDetectorInput(time_us=t_us, armed=armed, vel_ned_m_s=(vxy, 0.0, vz), rates_frd_rad_s=(rates, 0.0, 0.0),
                             specific_force_norm_m_s2=force, thrust_setpoint=thrust, hover_thrust=HOVER,
                             setpoint_vz_m_s=sp_vz, in_descent_mode=descent)


def flying_detector(params=None) -> LandDetector:
    det = LandDetector(params or default_registry())
    det.reset(landed=False)
    return det


def first_times(det: LandDetector, seconds: float, t0_us: int = 0, **kw) -> dict[str, float]:
    """Run constant inputs; the first time (s after t0) each flag became true."""
    seen: dict[str, float] = {}
    t = t0_us
    while t <= t0_us + seconds * 1e6:
        st = det.update(inp(t, **kw))
        for name in ("ground_contact", "maybe_landed", "landed", "freefall"):
            if getattr(st, name) and name not in seen:
                seen[name] = (t - t0_us) / 1e6
        t += STEP_US
    return seen


def test_disarmed_is_landed_after_the_usual_stages():
    # PX4 forces every condition true while disarmed; each stage's hysteresis still runs (in parallel)
    times = first_times(flying_detector(), 2.0, armed=False, thrust=0.0, vz=3.0, rates=5.0)
    assert times["landed"] == pytest.approx(1 / 3, abs=0.005)
    det = LandDetector(default_registry())  # boots landed
    st = det.update(inp(0, armed=False, thrust=0.0))
    assert st == LandDetectorState(landed=True, maybe_landed=True, ground_contact=True, freefall=False)


def test_landing_stages_take_a_third_of_lndmc_trig_time_each():
    times = first_times(flying_detector(), 2.0)
    assert times["ground_contact"] == pytest.approx(1 / 3, abs=0.005)
    assert times["maybe_landed"] == pytest.approx(2 / 3, abs=0.009)
    assert times["landed"] == pytest.approx(1.0, abs=0.013)
    assert "freefall" not in times


def test_trigger_time_parameter_scales_the_stages():
    params = default_registry()
    params.set("LNDMC_TRIG_TIME", 3.0)
    times = first_times(flying_detector(params), 4.0)
    assert times["ground_contact"] == pytest.approx(1.0, abs=0.005)
    assert times["landed"] == pytest.approx(3.0, abs=0.013)


def test_hovering_is_not_landed():
    times = first_times(flying_detector(), 3.0, thrust=HOVER, sp_vz=0.0)
    assert times == {}


def test_takeoff_is_detected_at_once():
    det = LandDetector(default_registry())
    assert det.update(inp(0, thrust=0.0)).landed  # boots landed
    st = det.update(inp(STEP_US, thrust=0.3, sp_vz=-1.0))  # thrust above the minimal-thrust level
    assert not st.landed and not st.maybe_landed


@pytest.mark.parametrize("kw", [
    {"sp_vz": 0.0},  # no descent commanded under climb-rate control
    {"sp_vz": math.nan},
    {"vz": 0.3},  # still moving down faster than LNDMC_Z_VEL_MAX
    {"vxy": 1.6},  # moving horizontally faster than LNDMC_XY_VEL_MAX
    {"thrust": 0.36},  # thrust above 60 % of the min..hover range
])
def test_ground_contact_needs_every_condition(kw):
    assert "ground_contact" not in first_times(flying_detector(), 2.0, **kw)


def test_without_climb_rate_control_no_descent_setpoint_is_needed():
    times = first_times(flying_detector(), 2.0, sp_vz=0.0, descent=False, thrust=0.05)
    assert times["landed"] == pytest.approx(1.0, abs=0.013)


def test_maybe_landed_needs_minimal_thrust_and_no_rotation():
    assert "maybe_landed" not in first_times(flying_detector(), 2.0, thrust=0.2)  # contact but not minimal
    times = first_times(flying_detector(), 2.0, rates=math.radians(25.0))
    assert "ground_contact" in times and "maybe_landed" not in times


def test_thresholds_widen_once_maybe_landed():
    det = flying_detector()
    first_times(det, 0.8)  # maybe landed by now
    st = det.update(inp(900_000, vz=0.5))  # 0.5 < 2.5 * 0.25: still in contact
    assert st.ground_contact and st.maybe_landed
    st = det.update(inp(904_000, vz=0.7))  # beyond the widened threshold: contact lost at once
    assert not st.ground_contact


def test_freefall_after_300_ms_blocks_landing():
    times = first_times(flying_detector(), 2.0, force=1.0)
    assert times["freefall"] == pytest.approx(0.3, abs=0.005)
    assert "maybe_landed" not in times


def test_reset_sets_the_state():
    det = LandDetector(default_registry())
    det.reset(landed=False)
    assert not det.state.landed
    det.reset()
    assert det.state.landed and det.state.ground_contact


def test_the_published_state_is_made_again_only_when_a_flag_changes():
    det = flying_detector()
    states = [det.update(inp(i * STEP_US)) for i in range(300)]  # 1.2 s of landing: contact, maybe landed, landed
    flags = [(s.landed, s.maybe_landed, s.ground_contact, s.freefall) for s in states]
    assert flags[-1] == (True, True, True, False)
    changes = 1 + sum(a != b for a, b in itertools.pairwise(flags))
    assert len({id(s) for s in states}) == changes == 4  # one read-only state per stage, shared in between
