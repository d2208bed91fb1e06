"""Conformance: MAVSDK's Mission plugin (the `mission` example) flies a plan on `sitl-emu serve` (issue 14): a
takeoff item and two waypoints near home uploaded, downloaded back and compared, arm, start_mission, mission_progress
followed to its end (current == total), is_mission_finished true, then clear_mission leaves the plan empty.
(test_mavsdk.py's session covers upload/download/clear without flying.)

MAVSDK's timeouts run on the wall clock, so the server runs only a few times faster than real time; the waits are
generous wall-clock bounds (a loaded 2-core machine), never timing asserts. The flight is about 20 simulated seconds.
"""

from __future__ import annotations

import asyncio
import math
from typing import Any

import pytest
from support.mavsdk_waits import call as _call
from support.mavsdk_waits import offset as _offset
from support.mavsdk_waits import wait as _wait
from support.serve_process import load_mavsdk

pytestmark = pytest.mark.slow  # processes or long flights: not in `make test-fast`

ALT_M = 8.0


@pytest.mark.timeout(300)
def test_mavsdk_mission_upload_download_fly_to_the_end_and_clear(mavsdk_port: int) -> None:
    mavsdk_asyncio = load_mavsdk()
    asyncio.run(asyncio.wait_for(_session(mavsdk_asyncio, mavsdk_port), timeout=240))


async def _session(mavsdk_asyncio: Any, port: int) -> None:
    from mavsdk.asyncio.plugins.action import ActionAsync
    from mavsdk.asyncio.plugins.mission import MissionAsync
    from mavsdk.asyncio.plugins.telemetry import TelemetryAsync

    config = mavsdk_asyncio.Configuration.create_with_component_type(mavsdk_asyncio.ComponentType.GROUND_STATION)
    async with mavsdk_asyncio.Mavsdk(config) as mavsdk:
        await _call(mavsdk.add_any_connection(f"udpin://0.0.0.0:{port}"))
        system = await asyncio.wait_for(mavsdk.first_autopilot(timeout_s=20.0), 25.0)
        assert system is not None, "MAVSDK found no autopilot"
        telemetry, action, mission = TelemetryAsync(system), ActionAsync(system), MissionAsync(system)
        await _wait("health_all_ok", telemetry.health_all_ok, bool, 60.0)
        home = await _call(telemetry.home())
        points = await _upload_and_compare(mission, home.latitude_deg, home.longitude_deg)
        assert not await _call(mission.is_mission_finished())
        await _call(action.arm())
        await _call(mission.start_mission())
        seen = await _follow_progress(mission, len(points))
        print(f"mission_progress (current, total) seen: {seen}")
        assert seen[-1] == (len(points), len(points)) and (1, len(points)) in seen
        assert await _call(mission.is_mission_finished())
        p = (await _call(telemetry.position_velocity_ned())).position
        last_n, last_e = points[-1][2], points[-1][3]
        assert math.hypot(p.north_m - last_n, p.east_m - last_e) < 5.0  # loitering at the last waypoint
        await _call(mission.clear_mission())
        plan = await _call(mission.download_mission())
        assert list(plan.mission_items) == []


async def _upload_and_compare(mission: Any, lat0: float, lon0: float) -> list[tuple[float, float, float, float]]:
    """Takeoff at home, then two waypoints 15 m away, at ALT_M and 5 m/s; the download gives the same items back."""
    from mavsdk.plugins.mission import MissionItem, MissionPlan

    nan = float("nan")
    offsets = [(0.0, 0.0), (15.0, 0.0), (15.0, 15.0)]
    points = [(*_offset(lat0, lon0, n, e), n, e) for n, e in offsets]
    actions = [MissionItem.VehicleAction.TAKEOFF] + [MissionItem.VehicleAction.NONE] * 2
    items = [MissionItem(lat, lon, ALT_M, 5.0, True, nan, nan, MissionItem.CameraAction.NONE, nan, nan, nan, nan,
                         nan, act) for (lat, lon, _, _), act in zip(points, actions, strict=True)]
    await _call(mission.set_return_to_launch_after_mission(False))
    await _call(mission.upload_mission(MissionPlan(items)))
    plan = await _call(mission.download_mission())
    got = [(i.latitude_deg, i.longitude_deg, i.relative_altitude_m, i.speed_m_s, i.vehicle_action)
           for i in plan.mission_items]
    assert got == [(pytest.approx(lat, abs=1e-7), pytest.approx(lon, abs=1e-7), pytest.approx(ALT_M),
                    pytest.approx(5.0), act) for (lat, lon, _, _), act in zip(points, actions, strict=True)]
    return points


async def _follow_progress(mission: Any, total: int) -> list[tuple[int, int]]:
    """(current, total) of every mission_progress update until current == total; never going backwards."""
    seen: list[tuple[int, int]] = []

    async def follow() -> None:
        async for progress in mission.subscribe_mission_progress():
            seen.append((progress.current, progress.total))
            if progress.total == total and progress.current == total:
                return

    try:
        await asyncio.wait_for(follow(), 150.0)
    except asyncio.TimeoutError as err:
        raise AssertionError(f"the mission did not reach its end; progress seen: {seen}") from err
    currents = [c for c, t in seen if t == total]
    assert currents == sorted(currents), seen
    return seen
