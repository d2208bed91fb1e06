"""Conformance: PX4's own SITL case "Return direct with geofence obstruction"
(PX4-Autopilot test/mavsdk_tests/test_multicopter_rtl_with_geofence.cpp, with autopilot_tester_rtl.cpp and
autopilot_tester.cpp) replayed with MAVSDK-Python against `sitl-emu serve`: the QGroundControl plan
multicopter_mission_geofence_avoid.plan imported by MAVSDK and moved to the vehicle, mission and fence uploaded,
GF_ACTION 1, RTL_TYPE 0, RTL_APPR_FORCE 0, arm, the mission started, Return when it reaches item 3; what the case
checks: disarmed within 400 s, the ground truth never breaks a fence shape, and it lands within 5 m of home."""

from __future__ import annotations

import asyncio
import math
from pathlib import Path
from typing import Any

import pytest
from support.geofence_avoid_plan import RTL_AT_SEQ, BreachMonitor, write_qgc_plan
from support.mavsdk_waits import MAVSDK_SPEED, Session, connect
from support.serve_process import load_mavsdk

from sitl_emu.geo import GeoRef, global_to_ned

pytestmark = pytest.mark.slow  # processes or long flights: not in `make test-fast`

# load_qgc_mission_and_geofence_here's is_global_position_frame
GLOBAL_POSITION_FRAMES = frozenset({0, 3, 5, 6, 10, 11})


@pytest.mark.timeout(400)
def test_px4s_return_with_geofence_obstruction_case(mavsdk_port: int, tmp_path: Path) -> None:
    mavsdk_asyncio = load_mavsdk()
    session = Session()
    plan_path = write_qgc_plan(tmp_path / "multicopter_mission_geofence_avoid.plan")
    try:
        asyncio.run(asyncio.wait_for(_case(mavsdk_asyncio, mavsdk_port, plan_path, session), timeout=380))
    finally:
        print("\nMAVSDK calls and outcomes:\n" + session.table())


async def _case(mavsdk_asyncio: Any, port: int, plan_path: Path, s: Session) -> None:
    from mavsdk.asyncio.plugins.action import ActionAsync
    from mavsdk.asyncio.plugins.param import ParamAsync
    from mavsdk.asyncio.plugins.telemetry import TelemetryAsync

    config = mavsdk_asyncio.Configuration.create_with_component_type(mavsdk_asyncio.ComponentType.GROUND_STATION)
    async with mavsdk_asyncio.Mavsdk(config) as mavsdk:
        system = await connect(mavsdk, port, s)  # wait_until_ready
        telemetry, params = TelemetryAsync(system), ParamAsync(system)
        await s.call("Telemetry.set_rate_ground_truth(15)", telemetry.set_rate_ground_truth(15.0))  # store_home
        home = await s.wait_for("a finite ground truth", telemetry.ground_truth,
                                lambda g: math.isfinite(g.latitude_deg), timeout_s=10)
        fence = await _load_plan_here(system, telemetry, plan_path, s)
        await s.call("Param.set_param_int(GF_ACTION, 1)", params.set_param_int("GF_ACTION", 1))
        await s.call("Param.set_param_int(RTL_TYPE, 0)", params.set_param_int("RTL_TYPE", 0))
        await s.call("Param.set_param_int(RTL_APPR_FORCE, 0)", params.set_param_int("RTL_APPR_FORCE", 0))
        await asyncio.sleep(3.0 / MAVSDK_SPEED)
        await s.call("Action.arm", ActionAsync(system).arm())
        ref = GeoRef(home.latitude_deg, home.longitude_deg, 0.0)
        monitor = BreachMonitor(fence, ref)
        watch = asyncio.create_task(_monitor(telemetry, monitor, ref))
        await _rtl_when_reaching(system, RTL_AT_SEQ, s)
        await s.wait_for("disarmed", telemetry.armed, lambda armed: not armed, timeout_s=400 / MAVSDK_SPEED + 30)
        watch.cancel()
        assert monitor.breach is None, f"GEOFENCE BREACH at NED {monitor.breach}"  # check_no_geofence_breach
        landed = await s.call("Telemetry.ground_truth", telemetry.ground_truth())
        north, east, _ = global_to_ned(ref, landed.latitude_deg, landed.longitude_deg, 0.0)
        assert math.hypot(north, east) < 5.0  # check_home_within(5.0)


async def _load_plan_here(system: Any, telemetry: Any, plan_path: Path, s: Session) -> list[Any]:
    """load_qgc_mission_and_geofence_here: the plan moved so that its first item is at the vehicle, uploaded."""
    from mavsdk.asyncio.plugins.mission_raw import MissionRawAsync

    mission_raw = MissionRawAsync(system)
    data = await s.call("MissionRaw.import_qgroundcontrol_mission",
                        mission_raw.import_qgroundcontrol_mission(str(plan_path)))
    pos = await s.wait_for("a finite position", telemetry.position, lambda p: math.isfinite(p.latitude_deg),
                           timeout_s=30)  # MAVSDK's first sample is NaN until GLOBAL_POSITION_INT has come
    first = data.mission_items[0]
    dx, dy = first.x - int(1e7 * pos.latitude_deg), first.y - int(1e7 * pos.longitude_deg)
    mission = [_moved(it, dx, dy) for it in data.mission_items]
    fence = [_moved(it, dx, dy) for it in data.geofence_items]
    await s.call(f"MissionRaw.upload_mission({len(mission)} items)", mission_raw.upload_mission(mission))
    await s.call(f"MissionRaw.upload_geofence({len(fence)} items)", mission_raw.upload_geofence(fence))
    return fence


def _moved(item: Any, dx: int, dy: int) -> Any:
    from mavsdk.plugins.mission_raw import MissionItem

    moves = item.frame in GLOBAL_POSITION_FRAMES
    return MissionItem(seq=item.seq, frame=item.frame, command=item.command, current=item.current,
                       autocontinue=item.autocontinue, param1=item.param1, param2=item.param2, param3=item.param3,
                       param4=item.param4, x=item.x - dx if moves else item.x, y=item.y - dy if moves else item.y,
                       z=item.z, mission_type=item.mission_type)


async def _monitor(telemetry: Any, monitor: BreachMonitor, ref: GeoRef) -> None:
    """start_monitoring_geofence_breach: every ground truth against the fence shapes."""
    async for truth in telemetry.subscribe_ground_truth():
        if math.isfinite(truth.latitude_deg) and math.isfinite(truth.longitude_deg):
            north, east, _ = global_to_ned(ref, truth.latitude_deg, truth.longitude_deg, 0.0)
            monitor.check(north, east)


async def _rtl_when_reaching(system: Any, seq: int, s: Session) -> None:
    """execute_rtl_when_reaching_mission_sequence: start the mission, wait for its progress at `seq`, Return."""
    from mavsdk.asyncio.plugins.action import ActionAsync
    from mavsdk.asyncio.plugins.mission_raw import MissionRawAsync

    mission_raw = MissionRawAsync(system)
    await s.call("MissionRaw.start_mission", mission_raw.start_mission())
    await s.wait_for(f"mission progress at {seq}", mission_raw.mission_progress, lambda p: p.current >= seq,
                     timeout_s=200 / MAVSDK_SPEED + 20)
    await s.call("Action.return_to_launch", ActionAsync(system).return_to_launch())
