"""Closed-loop fidelity of the manual modes against real PX4 (SITL + SIH): the four traces of
../shared/reference/px4-manual (a copy of its metrics.json is in tests/reference/px4-manual).

Each manoeuvre is flown as the probe flew it: MANUAL_CONTROL at 20 Hz (here straight into the vehicle), Position mode.
- takeoff: armed on the ground with the throttle full up at the same moment, 6 s, then centred;
- p_fwd: hovering, the right stick full forward for 4 s, then centred (speed, braking);
- p_yaw: the yaw stick full right for 2 s, then centred;
- land: NAV_LAND from about 29 m while centred sticks stream, until disarmed.
Tolerances as the other fidelity tests (tens of per cent): the emulator has no estimator or scheduling delays.
"""

from __future__ import annotations

import itertools
import json
import math
import statistics
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from sitl_emu.px4 import MavCmd, NavState
from sitl_emu.types import ManualControlSetpoint, VehicleCommand
from sitl_emu.vehicle.vehicle import Vehicle

PX4 = json.loads((Path(__file__).parents[2] / "reference" / "px4-manual" / "metrics.json").read_text())
NAN = math.nan
STICK_PERIOD_US = 50_000  # 20 Hz


def sticks(x: int = 0, y: int = 0, z: int = 500, r: int = 0) -> ManualControlSetpoint:
    """MANUAL_CONTROL's fields as PX4 reads them."""
    return ManualControlSetpoint(roll=y / 1000, pitch=x / 1000, yaw=r / 1000, throttle=z / 500 - 1)


@dataclass
class Flight:
    v: Vehicle = field(default_factory=Vehicle)
    current: ManualControlSetpoint = field(default_factory=sticks)
    t0_us: int = 0
    rows: list[tuple[float, tuple[float, float, float], tuple[float, float, float], float, bool]] = field(
        default_factory=list)

    def command(self, command: int, *params: float) -> None:
        self.v.handle_command(VehicleCommand(command, tuple(params) + (NAN,) * (7 - len(params))))

    def mark(self) -> None:
        """t = 0 of a manoeuvre; the recording starts afresh."""
        self.t0_us, self.rows = self.v.time_us, []

    def run(self, seconds: float) -> None:
        v = self.v
        end = v.time_us + round(seconds * 1e6)
        while v.time_us < end:
            if v.time_us % STICK_PERIOD_US == 0:
                v.manual_control_input(self.current)
            v.step()
            s = v.snapshot() if v.time_us % 20_000 == 0 else None
            if s is not None:
                self.rows.append(((v.time_us - self.t0_us) / 1e6, s.pos_ned_m, s.vel_ned_m_s, s.euler_rad[2], s.armed))

    def texts_since_mark(self) -> list[tuple[float, str]]:
        return [((e.time_us - self.t0_us) / 1e6, e.text) for e in self.v.events_after(0) if e.time_us >= self.t0_us]


def first(rows, predicate) -> float:
    return next(t for t, *rest in rows if predicate(t, *rest))


@pytest.fixture(scope="module")
def takeoff():
    f = Flight()
    f.run(2.5)
    f.command(MavCmd.DO_SET_MODE, 1, 3, 0)
    f.run(1.0)
    f.mark()
    f.current = sticks(z=1000)
    f.command(MavCmd.COMPONENT_ARM_DISARM, 1)
    f.run(6.0)
    f.current = sticks()
    f.run(6.0)
    return f


def test_throttle_takeoff_matches_px4(takeoff):
    ref, rows = PX4["takeoff"], takeoff.rows
    alt = {t: -p[2] for t, p, *_ in rows}
    release = max(t for t in alt if t <= 6.0)
    climb = [-vel[2] for t, _, vel, *_ in rows]
    assert first(rows, lambda t, p, *_: -p[2] > 0.05) == pytest.approx(ref["liftoff_delay_s"], rel=0.25)
    assert max(climb) == pytest.approx(ref["peak_climb_rate_ms"], rel=0.15)
    assert alt[release] == pytest.approx(ref["alt_gain_at_release_m"], rel=0.25)
    assert alt[max(alt)] == pytest.approx(ref["alt_gain_final_m"], rel=0.25)
    assert max(alt.values()) - alt[release] == pytest.approx(ref["alt_overshoot_after_release_m"], abs=0.4)
    detected = [t for t, text in takeoff.texts_since_mark() if text == "Takeoff detected"]
    assert detected and detected[0] == pytest.approx(ref["_info"]["texts_t_s"][0], abs=0.6)
    assert max(math.hypot(p[0], p[1]) for _, p, *_ in rows) < 0.2


@pytest.fixture(scope="module")
def forward(takeoff):
    f = takeoff
    f.run(4.0)
    f.mark()
    f.current = sticks(x=1000)
    f.run(4.0)
    f.current = sticks()
    f.run(8.0)
    return f


def test_forward_stick_speed_and_braking_match_px4(forward):
    ref, rows = PX4["p_fwd"], forward.rows
    x0, z0 = rows[0][1][0], rows[0][1][2]
    speed = {t: math.hypot(vel[0], vel[1]) for t, _, vel, *_ in rows}
    dist = {t: p[0] - x0 for t, p, *_ in rows}
    release = max(t for t in speed if t <= 4.0)
    assert max(speed.values()) == pytest.approx(ref["peak_speed_ms"], rel=0.15)
    assert first(rows, lambda t, p, vel, *_: math.hypot(vel[0], vel[1]) >= 1.0) == pytest.approx(
        ref["t_to_1ms_s"], rel=0.35)
    assert dist[release] == pytest.approx(ref["dist_at_release_m"], rel=0.2)
    assert dist[max(dist)] == pytest.approx(ref["final_dist_m"], rel=0.2)
    assert max(dist.values()) - dist[release] == pytest.approx(
        ref["max_excursion_m"] - ref["dist_at_release_m"], rel=0.3)
    assert max(abs(p[1]) for _, p, *_ in rows) < 0.5
    assert max(abs(p[2] - z0) for _, p, *_ in rows) < 0.5


@pytest.fixture(scope="module")
def yaw_turn(forward):
    f = forward
    f.mark()
    f.current = sticks(r=1000)
    f.run(2.0)
    f.current = sticks()
    f.run(4.0)
    return f


def test_yaw_stick_rate_matches_px4(yaw_turn):
    ref, rows = PX4["p_yaw"], yaw_turn.rows
    yaws = [(t, yaw) for t, _, _, yaw, _ in rows]
    unwrapped, total = [], 0.0
    for (_, a), (t, b) in itertools.pairwise(yaws):
        total += math.remainder(b - a, 2 * math.pi)
        unwrapped.append((t, math.degrees(total)))
    rates = [(t1, (y1 - y0) / (t1 - t0)) for (t0, y0), (t1, y1) in itertools.pairwise(unwrapped)]
    assert max(r for _, r in rates) == pytest.approx(ref["peak_yaw_rate_dps"], rel=0.1)
    at_release = max((t, y) for t, y in unwrapped if t <= 2.0)[1]
    assert at_release == pytest.approx(ref["yaw_change_at_release_deg"], rel=0.15)
    assert unwrapped[-1][1] == pytest.approx(ref["yaw_change_total_deg"], rel=0.15)
    p0 = rows[0][1]
    assert max(math.dist(p, p0) for _, p, *_ in rows) < 1.0


@pytest.mark.slow
def test_nav_land_while_sticks_stream_matches_px4(yaw_turn):
    ref, f = PX4["land"], yaw_turn
    f.current = sticks(z=1000)
    while -f.v.snapshot().pos_ned_m[2] < 28.8:  # the probe landed from about 29 m
        f.run(0.5)
    f.current = sticks()
    f.run(3.0)
    f.mark()
    f.command(MavCmd.NAV_LAND)
    f.run(40.0)
    texts = [text for _, text in f.texts_since_mark()]
    assert [t.rstrip("\t") for t in ref["texts"]] == [t for t in texts if t in
                                                     ("Landing at current position", "Landing detected",
                                                      "Disarmed by landing")]
    disarmed = next(t for t, text in f.texts_since_mark() if text == "Disarmed by landing")
    assert disarmed == pytest.approx(ref["t_disarmed_text_s"], rel=0.15)
    descent = [vel[2] for t, _, vel, _, armed in f.rows if armed and vel[2] > 0.3]
    assert statistics.median(descent) == pytest.approx(ref["median_descent_rate_ms"], rel=0.15)
    assert f.v.commander.nav_state is NavState.POSCTL  # back to the user's mode after disarming
