from __future__ import annotations

import dataclasses
import math

import pytest
from support.states import hover_state

from sitl_emu.params import default_registry
from sitl_emu.params.settings import sih_config
from sitl_emu.physics import GRAVITY_M_S2, RigidBodyState, SihConfig, step

DT = 0.004


def run(state, cmd, seconds, cfg):
    for _ in range(round(seconds / DT)):
        state = step(state, cmd, DT, cfg)
    return state


def test_config_comes_from_the_sih_parameters():
    reg = default_registry()
    reg.set("SIH_MASS", 1.5)
    cfg = sih_config(reg)
    assert cfg.mass_kg == 1.5
    assert cfg.t_max_n == 5.0 and cfg.t_tau_s == 0.05


def test_free_fall_matches_half_g_t_squared():
    cfg = SihConfig(kdv=0.0)
    state = RigidBodyState(pos_ned_m=(0.0, 0.0, -100.0), on_ground=False)
    end = run(state, (0.0, 0.0, 0.0, 0.0), 2.0, cfg)
    assert end.pos_ned_m[2] + 100.0 == pytest.approx(0.5 * GRAVITY_M_S2 * 4.0, rel=1e-3)
    assert end.vel_ned_m_s[2] == pytest.approx(GRAVITY_M_S2 * 2.0, rel=1e-3)
    assert end.specific_force_frd == pytest.approx((0.0, 0.0, 0.0), abs=1e-9)  # weightless


def test_hover_needs_about_049_per_motor_and_holds_altitude():
    cfg = SihConfig()
    assert cfg.hover_command == pytest.approx(0.49, abs=0.005)
    h = cfg.hover_command
    end = run(hover_state(5.0, cfg), (h, h, h, h), 10.0, cfg)
    assert end.pos_ned_m == pytest.approx((0.0, 0.0, -5.0), abs=1e-6)
    assert end.specific_force_frd[2] == pytest.approx(-GRAVITY_M_S2, rel=1e-6)


def test_step_does_not_change_its_input():
    cfg = SihConfig()
    state = hover_state(3.0, cfg)
    before = dataclasses.replace(state)
    step(state, (1.0, 1.0, 1.0, 1.0), DT, cfg)
    assert state == before


def test_motors_follow_the_command_with_the_sih_time_constant():
    cfg = SihConfig()
    end = run(RigidBodyState(), (1.0, 1.0, 1.0, 1.0), cfg.t_tau_s, cfg)
    assert end.motors[0] == pytest.approx(1.0 - math.exp(-1.0), abs=0.02)


def test_quaternion_stays_unit_over_a_long_spinning_run():
    cfg = SihConfig(kdw=0.0, kdv=0.0)
    state = RigidBodyState(pos_ned_m=(0.0, 0.0, -1e6), rates_frd_rad_s=(1.3, -0.7, 2.1), on_ground=False)
    h = cfg.hover_command
    end = run(state, (h, h, h, h), 60.0, cfg)
    assert math.fsum(c * c for c in end.q_wxyz) == pytest.approx(1.0, abs=1e-12)


def test_resting_on_the_ground_for_60_s_is_still_and_level():
    cfg = SihConfig()
    yaw = 0.7
    state = RigidBodyState(q_wxyz=(math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)))
    for cmd in ((0.0,) * 4, (0.3,) * 4, (0.45, 0.4, 0.45, 0.4)):
        end = run(state, cmd, 60.0, cfg)
        assert end.on_ground
        assert end.pos_ned_m == (0.0, 0.0, 0.0)
        assert end.vel_ned_m_s == (0.0, 0.0, 0.0)
        assert end.rates_frd_rad_s == (0.0, 0.0, 0.0)
        assert end.q_wxyz == pytest.approx(state.q_wxyz)


def test_landing_hard_stops_on_the_ground_without_bounce_and_levels():
    cfg = SihConfig()
    q = (math.cos(0.05), math.sin(0.05), 0.0, 0.0)  # 5.7 deg roll
    state = RigidBodyState(pos_ned_m=(0.0, 0.0, -0.1), vel_ned_m_s=(0.5, 0.0, 3.0), q_wxyz=q, on_ground=False)
    zs = []
    for _ in range(500):
        state = step(state, (0.2,) * 4, DT, cfg)
        zs.append(state.pos_ned_m[2])
    assert zs[0] < 0.0
    assert max(zs[20:]) == 0.0 and min(zs[20:]) == 0.0
    assert state.on_ground and state.vel_ned_m_s == (0.0, 0.0, 0.0)
    assert state.q_wxyz[1] == 0.0 and state.q_wxyz[2] == 0.0


def test_full_thrust_lifts_off_the_ground():
    cfg = SihConfig()
    end = run(RigidBodyState(), (0.8,) * 4, 1.0, cfg)
    assert not end.on_ground and end.pos_ned_m[2] < -1.0


def test_a_roll_torque_rolls_right_and_a_pitch_torque_pitches_up():
    cfg = SihConfig()
    h = cfg.hover_command
    d = 0.02
    # left motors (r1 rear-left, r2 front-left) up -> right wing down -> positive roll rate
    end = run(hover_state(10.0, cfg), (h - d, h + d, h + d, h - d), 0.2, cfg)
    assert end.rates_frd_rad_s[0] > 0.1 and abs(end.rates_frd_rad_s[1]) < 1e-9
    # front motors (r0, r2) up -> nose up -> positive pitch rate
    end = run(hover_state(10.0, cfg), (h + d, h - d, h + d, h - d), 0.2, cfg)
    assert end.rates_frd_rad_s[1] > 0.1 and abs(end.rates_frd_rad_s[0]) < 1e-9
    # r0, r1 up -> nose right -> positive yaw rate
    end = run(hover_state(10.0, cfg), (h + d, h + d, h - d, h - d), 0.2, cfg)
    assert end.rates_frd_rad_s[2] > 0.01


def test_a_right_roll_accelerates_the_vehicle_east():
    cfg = SihConfig()
    h = cfg.hover_command / math.cos(0.2)
    q = (math.cos(0.1), math.sin(0.1), 0.0, 0.0)  # 0.2 rad roll right
    state = dataclasses.replace(hover_state(10.0, cfg), q_wxyz=q)
    end = run(state, (h,) * 4, 0.5, cfg)
    assert end.vel_ned_m_s[1] > 0.5 and abs(end.vel_ned_m_s[2]) < 0.05


def test_drag_and_wind_set_a_terminal_drift_velocity():
    cfg = SihConfig(wind_n_m_s=3.0)  # SIH_WIND_N: from the north (sih.cpp: v_apparent = v + wind), blows south
    h = cfg.hover_command
    end = run(hover_state(50.0, cfg), (h,) * 4, 10.0, cfg)
    assert end.vel_ned_m_s[0] == pytest.approx(-3.0, abs=0.01)
