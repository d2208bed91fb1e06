"""Wind: Dryden turbulence statistics against MIL-F-8785C's spectra, gusts, parsing, and a hover in wind."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import signal

from sitl_emu.control.qmath import euler_from_q
from sitl_emu.disturbance.wind import (
    FT,
    DrydenTurbulence,
    Gust,
    WindModel,
    WindSettings,
    dryden_scales,
    parse_wind,
)
from sitl_emu.params import default_registry
from sitl_emu.physics import GRAVITY_M_S2
from sitl_emu.px4 import MavCmd
from sitl_emu.types import VehicleCommand
from sitl_emu.vehicle.vehicle import Vehicle

DT = 0.004
NAN = math.nan


def _psd_8785c(axis: int, sigma: float, length: float, v: float, omega: np.ndarray) -> np.ndarray:
    """MIL-F-8785C's one-sided Dryden spectra in rad/s, written out independently of the filters."""
    x = length * omega / v
    if axis == 0:
        return sigma**2 * 2.0 * length / (math.pi * v) / (1.0 + x**2)
    return sigma**2 * length / (math.pi * v) * (1.0 + 3.0 * x**2) / (1.0 + x**2) ** 2


def test_low_altitude_scales_follow_mil_f_8785c():
    s = dryden_scales(100 * FT, 15 * 0.514444)  # 100 ft, 15 kt at 20 ft: light
    k = 0.177 + 0.000823 * 100
    assert s.sigma[2] == pytest.approx(0.1 * 15 * 0.514444)
    assert s.sigma[0] == pytest.approx(s.sigma[2] / k**0.4)
    assert s.length_m[2] == pytest.approx(100 * FT)
    assert s.length_m[0] == pytest.approx(100 / k**1.2 * FT)
    high = dryden_scales(3000 * FT, 10.0)  # above 2000 ft: isotropic, 1750 ft
    assert high.length_m == pytest.approx((1750 * FT,) * 3) and high.sigma == pytest.approx((1.0,) * 3)


@pytest.fixture(scope="module")
def long_run() -> np.ndarray:
    """10 000 s of turbulence at 50 m in a 10 m/s wind (2.5 M samples), seeded."""
    turb = DrydenTurbulence(15.4, 10.0, DT, np.random.default_rng(1))
    return np.concatenate([turb.block(50.0, 25_000) for _ in range(100)])


@pytest.mark.slow
def test_variance_matches_the_dryden_intensities_within_10_percent(long_run: np.ndarray):
    s = dryden_scales(49.0 + 1.0, 15.4)  # the filters use the middle of the 2 m band
    assert long_run.var(axis=0) == pytest.approx(np.square(s.sigma), rel=0.10)
    assert abs(long_run.mean(axis=0)).max() < 0.2 * min(s.sigma)


@pytest.mark.slow
def test_spectrum_matches_the_dryden_spectrum(long_run: np.ndarray):
    s = dryden_scales(50.0, 15.4)
    f, p = signal.welch(long_run, fs=1.0 / DT, nperseg=2**16, axis=0)
    band = (f > 0.05) & (f < 10.0)
    for axis in range(3):
        want = _psd_8785c(axis, s.sigma[axis], s.length_m[axis], 10.0, 2 * math.pi * f[band])
        ratio = p[band, axis] / (2 * math.pi) / want  # welch: per Hz -> per rad/s
        assert np.median(ratio) == pytest.approx(1.0, abs=0.1), axis


def test_same_seed_same_wind_and_another_seed_another():
    def series(seed: int) -> list[tuple[float, float, float]]:
        m = WindModel(WindSettings(5.0, 270.0, 7.7), DT, np.random.default_rng(seed))
        return [m.sample(i * 4000, 20.0, (0.0, 0.0)) for i in range(600)]
    assert series(3) == series(3) and series(3) != series(4)


def test_mean_wind_direction_and_sih_wind_from_components():
    m = WindModel(WindSettings(5.0, 270.0), DT, np.random.default_rng(0))
    n, e, d = m.sample(0, 10.0, (0.0, 0.0))
    assert (n, e, d) == pytest.approx((0.0, 5.0, 0.0))  # from the west: the air moves east
    assert m.sample(4000, 10.0, (2.0, 0.0)) == pytest.approx((-2.0, 5.0, 0.0))  # SIH_WIND_N 2: from the north


def test_gust_is_a_1_cosine_step():
    g = Gust(start_s=1.0, ramp_s=2.0, amplitude_ned_m_s=(0.0, 4.0, 0.0))
    assert [g.at(t) for t in (0.5, 1.0, 2.0, 3.0, 10.0)] == pytest.approx([0.0, 0.0, 0.5, 1.0, 1.0])
    m = WindModel(WindSettings(gusts=(g,)), DT, np.random.default_rng(0))
    assert m.sample(2_000_000, 10.0, (0.0, 0.0)) == pytest.approx((0.0, 2.0, 0.0))


@pytest.mark.parametrize(("text", "want"), [("5@270", (5.0, 270.0, 0.0)), ("3,-90", (3.0, 270.0, 0.0)),
                                            ("5@270,light", (5.0, 270.0, 15 * 0.514444)),
                                            ("5@0,2.5", (5.0, 0.0, 2.5))])
def test_parse_wind(text: str, want: tuple[float, float, float]):
    w = parse_wind(text)
    assert (w.speed_m_s, w.from_deg, w.turbulence_w20_m_s) == pytest.approx(want)


@pytest.mark.parametrize("text", ["5", "a@b", "-1@0", "5@270,storm", "1,2,3,4", "5@999", "5@-400", "5@nan", "inf@0",
                                  "1e9@270", "100.5@0", "5@270,1e9", "5@270,-1"])
def test_parse_wind_refuses(text: str):
    with pytest.raises(ValueError):
        parse_wind(text)


@pytest.mark.parametrize(("text", "blamed"), [("5@inf", "direction"), ("5@nan", "direction"), ("5@-inf", "direction"),
                                              ("5@400", "direction"), ("inf@270", "speed"), ("nan@270", "speed"),
                                              ("101@270", "speed")])
def test_parse_wind_blames_the_field_that_is_wrong(text: str, blamed: str):
    with pytest.raises(ValueError, match=f"wind '{text}': the {blamed} "):
        parse_wind(text)


def _hover(wind: WindSettings | None, seconds: float) -> Vehicle:
    v = Vehicle(wind=wind)
    v.run_for(2.5)
    v.handle_command(VehicleCommand(MavCmd.COMPONENT_ARM_DISARM, (1.0, 0.0) + (NAN,) * 5))
    v.handle_command(VehicleCommand(MavCmd.NAV_TAKEOFF, (NAN,) * 7))
    v.run_for(seconds)
    return v


def test_hover_in_a_5_m_s_wind_tilts_into_it_and_holds_position():
    v = _hover(WindSettings(5.0, 270.0), 30.0)  # from the west
    s = v.snapshot()
    roll, pitch, _ = euler_from_q(s.q_wxyz)
    # the drag of 5 m/s air on SIH's KDV 1 N/(m/s) needs a 5 N push west from the thrust: tilt atan(5 / (m g))
    assert roll == pytest.approx(-math.atan(5.0 / GRAVITY_M_S2), abs=math.radians(3))
    assert abs(pitch) < math.radians(3)
    assert math.hypot(s.pos_ned_m[0], s.pos_ned_m[1]) < 0.5  # Hold keeps the takeoff point
    assert s.pos_ned_m[2] == pytest.approx(-2.5, abs=0.3)


@pytest.mark.slow
def test_hover_in_turbulence_stays_near_and_calm_air_stays_level():
    v = _hover(WindSettings(3.0, 0.0, 7.7), 30.0)
    s = v.snapshot()
    assert math.hypot(s.pos_ned_m[0], s.pos_ned_m[1]) < 2.0
    calm = _hover(None, 10.0).snapshot()
    assert max(abs(a) for a in euler_from_q(calm.q_wxyz)[:2]) < 1e-3


def test_with_only_the_attitude_controlled_the_wind_carries_the_vehicle_downwind():
    from sitl_emu.px4 import NavState, custom_mode, decode_custom_mode
    from sitl_emu.types import AttitudeSetpoint, OffboardControlMode

    v = _hover(WindSettings(5.0, 270.0), 10.0)
    e0 = v.snapshot().pos_ned_m[1]
    mode = OffboardControlMode(attitude=True)
    level = AttitudeSetpoint(q_wxyz=(1.0, 0.0, 0.0, 0.0), thrust_body=(0.0, 0.0, -0.5))
    v.offboard_input(mode, attitude=level)
    main, sub = decode_custom_mode(custom_mode(NavState.OFFBOARD))
    v.handle_command(VehicleCommand(MavCmd.DO_SET_MODE, (1.0, main, sub) + (NAN,) * 4))
    for _ in range(60):  # 3 s of level attitude, no position control
        v.offboard_input(mode, attitude=level)
        v.run_for(0.05)
    s = v.snapshot()
    assert s.nav_state is NavState.OFFBOARD
    assert s.pos_ned_m[1] - e0 > 3.0 and s.vel_ned_m_s[1] > 2.0  # blown east, towards the wind's 5 m/s


@pytest.mark.slow
def test_a_take_off_in_8_m_s_of_wind_drifts_as_far_and_comes_back_as_fast_as_px4_sih():
    """PX4 SIH with SIH_WIND_N = 8 and `commander takeoff` (px4-recorded-facts.md 1): blown 11.1 m downwind (11.2 m in
    a second run), the farthest ~4 s after lift-off, back within 1 m 13 s after that, 39 deg of tilt while it holds.
    That is PX4's controller, not a weak one: until the takeoff ramp ends the tilt limit is MPC_TILTMAX_LND, 12 deg
    (MulticopterPositionControl.cpp, then a 0.2 rad/s slew to MPC_TILTMAX_AIR), and SIH's linear drag KDV x the air
    velocity (sih.cpp) needs atan(8 / 9.81) = 39 deg. Issue 25.2 asked whether the emulator's 12.6 m was too weak."""
    reg = default_registry()
    reg.set("SIH_WIND_N", 8.0)  # from the north: the vehicle is blown south (x < 0)
    v = Vehicle(params=reg)
    v.run_for(2.5)
    v.handle_command(VehicleCommand(MavCmd.COMPONENT_ARM_DISARM, (1.0, 0.0) + (NAN,) * 5))
    v.handle_command(VehicleCommand(MavCmd.NAV_TAKEOFF, (NAN,) * 7))
    track = []
    for _ in range(400):  # 40 s
        v.run_for(0.1)
        s = v.snapshot()
        track.append((v.time_us / 1e6, s.pos_ned_m, euler_from_q(s.q_wxyz)[1]))
    liftoff_s = next(t for t, p, _ in track if p[2] < -0.05)
    far_s, far, _ = min(track, key=lambda row: row[1][0])
    back_s = next(t for t, p, _ in track if t > far_s and abs(p[0]) < 1.0)
    assert 9.5 < -far[0] < 14.0  # PX4: 11.1 m; the emulator 12.6 m
    assert 3.0 < far_s - liftoff_s < 6.0  # PX4: ~4 s
    assert 9.0 < back_s - far_s < 16.0  # PX4: 13 s
    assert math.degrees(track[-1][2]) == pytest.approx(-39.1, abs=1.5)  # pitched into the wind, as PX4
