"""Estimator noise: white noise and a wandering bias on the estimate, the truth untouched; off by default."""

from __future__ import annotations

import math

import numpy as np
import pytest
from support.states import hover_state

from sitl_emu.disturbance.estimate import EstimateNoise, EstimateNoiseSettings
from sitl_emu.px4 import LandedState, MavCmd
from sitl_emu.types import VehicleCommand
from sitl_emu.vehicle.vehicle import Vehicle

NAN = math.nan


def test_white_noise_and_bias_walk_statistics():
    truth = hover_state(10.0)
    noise = EstimateNoise(EstimateNoiseSettings(pos_white_m=0.3, vel_walk_m_s=0.1), np.random.default_rng(5))
    dt, n = 0.004, 25_000  # 100 s
    est = [noise.apply(truth, dt) for _ in range(n)]
    pos = np.array([e.pos_ned_m for e in est]) - truth.pos_ned_m
    vel = np.array([e.vel_ned_m_s for e in est])
    assert pos.std(axis=0) == pytest.approx([0.3] * 3, rel=0.05)
    assert abs(pos.mean(axis=0)).max() < 0.02
    # a random walk: its increments over 1 s have the walk intensity as their std (0.1 / sqrt(s))
    steps = vel[250::250] - vel[:-250:250]
    assert steps.std() == pytest.approx(0.1, rel=0.15)
    assert est[-1].q_wxyz == truth.q_wxyz  # no attitude noise asked for


def test_the_default_is_the_truth_and_noise_moves_only_the_estimate():
    def fly(noise: EstimateNoiseSettings | None) -> Vehicle:
        v = Vehicle(estimate_noise=noise, seed=2)
        v.run_for(2.5)
        v.handle_command(VehicleCommand(MavCmd.COMPONENT_ARM_DISARM, (1.0, 0.0) + (NAN,) * 5))
        v.handle_command(VehicleCommand(MavCmd.NAV_TAKEOFF, (NAN,) * 7))
        v.run_for(15.0)
        return v

    calm = fly(None)
    assert calm.snapshot().pos_ned_m == calm._state.pos_ned_m
    noisy = fly(EstimateNoiseSettings(pos_white_m=0.05, pos_walk_m=0.05, att_white_rad=0.002))
    s, truth = noisy.snapshot(), noisy._state
    assert s.pos_ned_m != truth.pos_ned_m and s.q_wxyz != truth.q_wxyz
    assert math.dist(s.pos_ned_m, truth.pos_ned_m) < 1.0  # the controllers fly on the estimate, still nearby
    assert truth.pos_ned_m[2] == pytest.approx(-2.5, abs=1.0)


def test_on_the_ground_the_estimate_is_as_noisy_as_in_flight():
    # PX4's EKF2 keeps fusing GNSS and the barometer while landed: the estimate wanders on the pad, the truth rests
    v = Vehicle(estimate_noise=EstimateNoiseSettings(pos_white_m=0.1, vel_white_m_s=0.05), seed=4)
    errors, speeds = [], []
    for _ in range(500):  # 2 s, disarmed on the ground
        v.step()
        truth, est = v._state, v.estimate
        assert truth.on_ground and truth.pos_ned_m == (0.0, 0.0, 0.0)
        errors.append(np.subtract(est.pos_ned_m, truth.pos_ned_m))
        speeds.append(est.vel_ned_m_s)
    assert np.std(errors, axis=0) == pytest.approx([0.1] * 3, rel=0.15)
    assert np.std(speeds, axis=0) == pytest.approx([0.05] * 3, rel=0.15)
    assert v.snapshot().landed_state is LandedState.ON_GROUND  # the commander still sees it landed


def test_position_white_noise_is_one_normal_draw_per_axis_and_tick_from_the_seeds_own_stream():
    # the draws the former Vehicle(position_noise_m) made, so seeded noisy flights fly as before
    v = Vehicle(estimate_noise=EstimateNoiseSettings(pos_white_m=0.3), seed=9)
    rng = np.random.default_rng(9)
    for _ in range(50):
        v.step()
        n = rng.normal(0.0, 0.3, 3)
        truth = v._state.pos_ned_m
        assert v.estimate.pos_ned_m == (truth[0] + float(n[0]), truth[1] + float(n[1]), truth[2] + float(n[2]))
        assert v.estimate.vel_ned_m_s == v._state.vel_ned_m_s and v.estimate.q_wxyz == v._state.q_wxyz


def test_levels_from_plain_data_and_their_one_sentence_errors():
    assert EstimateNoiseSettings.from_mapping({"pos_white_m": 1, "att_walk_rad": 0.5}) == EstimateNoiseSettings(
        pos_white_m=1.0, att_walk_rad=0.5)
    with pytest.raises(ValueError, match="estimate_noise has no level 'position_noise_m'; the levels are pos_white_m"):
        EstimateNoiseSettings.from_mapping({"position_noise_m": 0.3})
    for bad in (-0.1, math.inf, NAN, "0.3", True):
        with pytest.raises(ValueError, match="estimate_noise pos_white_m must be a number from 0 up"):
            EstimateNoiseSettings.from_mapping({"pos_white_m": bad})
