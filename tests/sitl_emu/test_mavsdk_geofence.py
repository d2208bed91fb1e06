"""Conformance: MAVSDK's geofence plugin (the `geofence` example) against `sitl-emu serve`: a polygon and a circle
uploaded and downloaded back, GF_ACTION set to Return: goto_location outside the fence is refused by the navigator
("Reposition is outside geofence"); with GF_ACTION None it is flown, and setting GF_ACTION back to Return there is a
breach handled as PX4 handles it (the breach text, the Hold of COM_FAIL_ACT_T, Return, landing at home).

MAVSDK's timeouts run on the wall clock, so the server runs only a few times faster than real time. The test skips
only when the MAVSDK library cannot be loaded on this machine.
"""

from __future__ import annotations

import asyncio
import math
import time
from typing import Any

import pytest
from support.mavsdk_waits import call as _call
from support.mavsdk_waits import offset as _offset
from support.mavsdk_waits import wait as _wait
from support.serve_process import load_mavsdk

pytestmark = pytest.mark.slow  # processes or long flights: not in `make test-fast`


@pytest.mark.timeout(300)
def test_mavsdk_geofence_breach_returns(mavsdk_port: int) -> None:
    mavsdk_asyncio = load_mavsdk()
    asyncio.run(asyncio.wait_for(_fly(mavsdk_asyncio, mavsdk_port), timeout=240))


async def _fly(mavsdk_asyncio: Any, port: int) -> None:
    from mavsdk.asyncio.plugins.action import ActionAsync
    from mavsdk.asyncio.plugins.param import ParamAsync
    from mavsdk.asyncio.plugins.telemetry import TelemetryAsync

    config = mavsdk_asyncio.Configuration.create_with_component_type(mavsdk_asyncio.ComponentType.GROUND_STATION)
    async with mavsdk_asyncio.Mavsdk(config) as mavsdk:
        await _call(mavsdk.add_any_connection(f"udpin://0.0.0.0:{port}"))
        system = await asyncio.wait_for(mavsdk.first_autopilot(timeout_s=20.0), 25.0)
        assert system is not None, "MAVSDK found no autopilot"
        telemetry, action = TelemetryAsync(system), ActionAsync(system)
        await _wait("health_all_ok", telemetry.health_all_ok, bool, 30.0)
        texts: list[str] = []
        reader = asyncio.create_task(_collect_texts(telemetry, texts))
        home = await _call(telemetry.home())
        await _upload_fence(system, home.latitude_deg, home.longitude_deg)
        param = ParamAsync(system)
        await _call(param.set_param_int("GF_ACTION", 3))  # Return
        await _call(action.arm())
        await _call(action.takeoff())
        await _wait("in_air", telemetry.in_air, bool, 20.0)
        await asyncio.sleep(3.0)
        lat, lon = _offset(home.latitude_deg, home.longitude_deg, 60.0, 0.0)
        await _call(action.goto_location(lat, lon, home.absolute_altitude_m + 5.0, math.nan))
        await _wait("the refusal", lambda: _value(texts), lambda t: "Reposition is outside geofence" in t, 10.0)
        await _call(param.set_param_int("GF_ACTION", 0))  # None: no check of the target, no breach
        await _call(action.goto_location(lat, lon, home.absolute_altitude_m + 5.0, math.nan))
        await _wait("60 m north", lambda: _north(telemetry), lambda n: n > 58.0, 60.0)
        assert not any(t.startswith("Geofence") for t in texts)
        await _call(param.set_param_int("GF_ACTION", 3))
        await _breach_handled(telemetry, texts)
        reader.cancel()


async def _value(value: Any) -> Any:
    return value


async def _north(telemetry: Any) -> float:
    return float((await _call(telemetry.position_velocity_ned())).position.north_m)


async def _collect_texts(telemetry: Any, texts: list[str]) -> None:
    async for status in telemetry.subscribe_status_text():
        texts.append(status.text.rstrip("\t"))  # PX4's tab: the text is also an event


async def _upload_fence(system: Any, lat: float, lon: float) -> None:
    """MAVSDK's geofence example: an inclusion polygon (a 60 m square around home) and an exclusion circle."""
    from mavsdk.asyncio.plugins.geofence import GeofenceAsync
    from mavsdk.plugins.geofence import Circle, FenceType, GeofenceData, Point, Polygon

    corners = [_offset(lat, lon, n, e) for n, e in ((-30, -30), (-30, 30), (30, 30), (30, -30))]
    polygon = Polygon([Point(a, b) for a, b in corners], FenceType.INCLUSION)
    circle = Circle(Point(*_offset(lat, lon, 0.0, -20.0)), 5.0, FenceType.EXCLUSION)
    geofence = GeofenceAsync(system)
    await _call(geofence.upload_geofence(GeofenceData([polygon], [circle])))
    got = await _call(geofence.download_geofence())
    assert len(got.polygons) == 1 and len(got.polygons[0].points) == 4 and len(got.circles) == 1
    assert got.circles[0].radius == pytest.approx(5.0)
    assert got.polygons[0].fence_type == FenceType.INCLUSION and got.circles[0].fence_type == FenceType.EXCLUSION


async def _breach_handled(telemetry: Any, texts: list[str]) -> None:
    from mavsdk.plugins.telemetry import FlightMode

    await _wait("flight mode HOLD (the failsafe's delay)", telemetry.flight_mode, lambda m: m == FlightMode.HOLD, 30.0)
    await _wait("flight mode RETURN_TO_LAUNCH", telemetry.flight_mode, lambda m: m == FlightMode.RETURN_TO_LAUNCH,
                30.0)
    wanted = ("Geofence: approaching or outside geofence", "Failsafe activated: entering Hold for 5 seconds",
              "Failsafe activated")
    deadline = time.monotonic() + 10.0  # the texts come on their own subscription, maybe after the mode change
    while not all(text in texts for text in wanted) and time.monotonic() < deadline:
        await asyncio.sleep(0.1)
    assert all(text in texts for text in wanted), texts
    await _wait("landed and disarmed", telemetry.armed, lambda armed: not armed, 120.0)
    p = (await _call(telemetry.position_velocity_ned())).position
    assert math.hypot(p.north_m, p.east_m) < 1.5
