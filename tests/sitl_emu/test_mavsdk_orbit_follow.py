"""MAVSDK's `action.do_orbit` (COMMAND_INT DO_ORBIT) and `follow_me` (FLW_TGT_* parameters, AUTO.FOLLOW_TARGET,
FOLLOW_TARGET stream) against `sitl-emu serve`, as test_mavsdk.py runs MAVSDK (wall-clock timeouts, the server a
few times faster than real time). Skips only when the MAVSDK library cannot be loaded."""

from __future__ import annotations

import asyncio
import math
from typing import Any

import pytest
from support.mavsdk_waits import MAVSDK_SPEED, Session, connect
from support.serve_process import load_mavsdk

from sitl_emu.geo import EARTH_RADIUS_M

pytestmark = pytest.mark.slow  # processes or long flights: not in `make test-fast`

EARTH_M_PER_DEG = math.radians(1.0) * EARTH_RADIUS_M


def test_mavsdk_orbits_a_point_and_follows_a_target(mavsdk_port: int) -> None:
    mavsdk_asyncio = load_mavsdk()
    session = Session()
    try:
        asyncio.run(asyncio.wait_for(_fly(mavsdk_asyncio, mavsdk_port, session), timeout=300))
    finally:
        print("\nMAVSDK calls and outcomes:\n" + session.table())


async def _fly(mavsdk_asyncio: Any, port: int, s: Session) -> None:
    from mavsdk.asyncio.plugins.action import ActionAsync
    from mavsdk.asyncio.plugins.follow_me import FollowMeAsync
    from mavsdk.asyncio.plugins.telemetry import TelemetryAsync

    config = mavsdk_asyncio.Configuration.create_with_component_type(mavsdk_asyncio.ComponentType.GROUND_STATION)
    async with mavsdk_asyncio.Mavsdk(config) as mavsdk:
        system = await connect(mavsdk, port, s)
        telemetry, action = TelemetryAsync(system), ActionAsync(system)
        await s.call("Action.arm", action.arm())
        await s.call("Action.takeoff", action.takeoff())
        await s.wait_for("in_air", telemetry.in_air, bool, timeout_s=20)
        await s.wait_for("up ~2.5 m", telemetry.position, lambda p: abs(p.relative_altitude_m - 2.5) < 0.3, 30)
        home = await telemetry.position()
        await _orbit(telemetry, action, home, s)
        await _follow(telemetry, FollowMeAsync(system), home, s)


def _offset(home: Any, north_m: float, east_m: float) -> tuple[float, float]:
    return (home.latitude_deg + north_m / EARTH_M_PER_DEG,
            home.longitude_deg + east_m / (EARTH_M_PER_DEG * math.cos(math.radians(home.latitude_deg))))


def _distance_m(p: Any, lat: float, lon: float) -> float:
    dn = (p.latitude_deg - lat) * EARTH_M_PER_DEG
    de = (p.longitude_deg - lon) * EARTH_M_PER_DEG * math.cos(math.radians(lat))
    return math.hypot(dn, de)


async def _orbit(telemetry: Any, action: Any, home: Any, s: Session) -> None:
    from mavsdk.plugins.action import OrbitYawBehavior
    from mavsdk.plugins.telemetry import FlightMode

    lat, lon = _offset(home, 15.0, 0.0)
    await s.call("Action.do_orbit(8 m, 2 m/s, centre 15 m north)",
                 action.do_orbit(8.0, 2.0, OrbitYawBehavior.HOLD_FRONT_TO_CIRCLE_CENTER, lat, lon,
                                 home.absolute_altitude_m))
    await s.wait_for("out of Hold (MAVSDK shows POSCTL.ORBIT as POSCTL)", telemetry.flight_mode,
                     lambda m: m == FlightMode.POSCTL, timeout_s=5)
    await s.wait_for("on the 8 m circle", telemetry.position, lambda p: abs(_distance_m(p, lat, lon) - 8.0) < 1.0,
                     timeout_s=60)
    for _ in range(10):  # it stays on it
        await asyncio.sleep(0.5)
        assert abs(_distance_m(await telemetry.position(), lat, lon) - 8.0) < 1.2
    await s.call("Action.hold", action.hold())
    await s.wait_for("flight mode HOLD", telemetry.flight_mode, lambda m: m == FlightMode.HOLD, timeout_s=5)


async def _follow(telemetry: Any, follow_me: Any, home: Any, s: Session) -> None:
    from mavsdk.plugins.follow_me import Config, TargetLocation
    from mavsdk.plugins.telemetry import FlightMode

    config = Config(follow_height_m=10.0, follow_distance_m=6.0, responsiveness=0.1,
                    altitude_mode=Config.FollowAltitudeMode.CONSTANT, max_tangential_vel_m_s=5.0,
                    follow_angle_deg=180.0)
    await s.call("FollowMe.set_config(height 10, distance 6)", follow_me.set_config(config))
    north, speed = 0.0, 1.5
    lat, lon = _offset(home, north, 20.0)
    await s.call("FollowMe.start", follow_me.start())  # DO_SET_MODE AUTO.FOLLOW_TARGET
    await s.wait_for("flight mode FOLLOW_ME", telemetry.flight_mode, lambda m: m == FlightMode.FOLLOW_ME, 5)
    await s.call("FollowMe.set_target_location", follow_me.set_target_location(
        TargetLocation(lat, lon, home.absolute_altitude_m - 2.5, speed, 0.0, 0.0)))
    distances, heights = [], []
    for i in range(60):  # the target walks north at 1.5 m/s for 30 s (of wall time: the server runs faster)
        await asyncio.sleep(0.5)
        north += speed * 0.5 * MAVSDK_SPEED
        lat, lon = _offset(home, north, 20.0)
        await follow_me.set_target_location(TargetLocation(lat, lon, home.absolute_altitude_m - 2.5, speed, 0, 0))
        if i >= 40:
            p = await telemetry.position()
            distances.append(_distance_m(p, lat, lon))
            heights.append(p.relative_altitude_m)
    assert all(abs(h - 10.0) < 1.0 for h in heights), heights
    # near the target: 6 m behind it, plus the lag of a stream paced on the wall clock while the server's simulated
    # time may fall behind its --speed on a loaded machine (the target then moves faster in simulated time)
    assert all(d < 15.0 for d in distances), distances
    assert (await telemetry.position()).latitude_deg > _offset(home, 20.0, 0.0)[0]  # it did go north with it
    await s.call("FollowMe.stop", follow_me.stop())
    await s.wait_for("flight mode HOLD", telemetry.flight_mode, lambda m: m == FlightMode.HOLD, timeout_s=5)
