"""Conformance: MAVSDK's ground truth (Telemetry.set_rate_ground_truth / ground_truth), what PX4's own SITL test
harness asks first (test/mavsdk_tests/autopilot_tester.cpp store_home: set_rate_ground_truth(15), then the ground
truth's latitude and longitude as home). PX4 serves it as HIL_STATE_QUATERNION from SIH's groundtruth topics.
Then the harness's "Offboard takeoff and land" (test_multicopter_offboard.cpp), whose last check reads the ground
truth again: back within 2 m of home."""

from __future__ import annotations

import asyncio
import math
from typing import Any

import pytest
from support.mavsdk_waits import Session, connect
from support.serve_process import load_mavsdk

pytestmark = pytest.mark.slow  # processes or long flights: not in `make test-fast`

HOME_LAT_DEG, HOME_LON_DEG = 47.397742, 8.545594  # SIH_LOC_LAT0 / SIH_LOC_LON0


@pytest.mark.timeout(180)
def test_mavsdk_ground_truth_as_px4s_offboard_takeoff_and_land_case_reads_it(mavsdk_port: int) -> None:
    mavsdk_asyncio = load_mavsdk()
    session = Session()
    try:
        asyncio.run(asyncio.wait_for(_ground_truth(mavsdk_asyncio, mavsdk_port, session), timeout=150))
    finally:
        print("\nMAVSDK calls and outcomes:\n" + session.table())


async def _ground_truth(mavsdk_asyncio: Any, port: int, s: Session) -> None:
    from mavsdk.asyncio.plugins.telemetry import TelemetryAsync

    config = mavsdk_asyncio.Configuration.create_with_component_type(mavsdk_asyncio.ComponentType.GROUND_STATION)
    async with mavsdk_asyncio.Mavsdk(config) as mavsdk:
        system = await connect(mavsdk, port, s)
        telemetry = TelemetryAsync(system)
        await s.call("Telemetry.set_rate_ground_truth(15)", telemetry.set_rate_ground_truth(15.0))
        home = await s.wait_for("a finite ground truth", telemetry.ground_truth,
                                lambda g: math.isfinite(g.latitude_deg) and math.isfinite(g.longitude_deg),
                                timeout_s=10)
        assert home.latitude_deg == pytest.approx(HOME_LAT_DEG, abs=1e-6)
        assert home.longitude_deg == pytest.approx(HOME_LON_DEG, abs=1e-6)
        assert 480.0 < home.absolute_altitude_m < 500.0  # AMSL on the ground at SIH_LOC_H0
        await _offboard_takeoff_and_land(system, telemetry, home, s)


async def _offboard_takeoff_and_land(system: Any, telemetry: Any, home: Any, s: Session) -> None:
    from mavsdk.asyncio.plugins.action import ActionAsync
    from mavsdk.asyncio.plugins.offboard import OffboardAsync
    from mavsdk.asyncio.plugins.param import ParamAsync
    from mavsdk.plugins.offboard import PositionNedYaw, VelocityNedYaw

    action, offboard = ActionAsync(system), OffboardAsync(system)
    await s.call("Param.set_param_int(COM_RCL_EXCEPT, 4)", ParamAsync(system).set_param_int("COM_RCL_EXCEPT", 4))
    await s.wait_for("armable", telemetry.health, lambda h: h.is_armable, timeout_s=20)
    await s.call("Action.arm", action.arm())
    await s.call("Offboard.set_position_ned(0, 0, -2)", offboard.set_position_ned(PositionNedYaw(0, 0, -2, 0)))
    await s.call("Offboard.start", offboard.start())
    await s.wait_for("within 0.3 m of (0, 0, -2)", telemetry.position_velocity_ned,
                     lambda p: math.dist((p.position.north_m, p.position.east_m, p.position.down_m), (0, 0, -2)) < 0.3,
                     timeout_s=30)
    up = await s.call("Telemetry.ground_truth", telemetry.ground_truth())
    assert up.absolute_altitude_m == pytest.approx(home.absolute_altitude_m + 2.0, abs=0.4)  # live, not the boot value
    await s.call("Offboard.set_velocity_ned(down 1 m/s)", offboard.set_velocity_ned(VelocityNedYaw(0, 0, 1, 0)))
    await s.wait_for("disarmed", telemetry.armed, lambda armed: not armed, timeout_s=40)
    landed = await s.call("Telemetry.ground_truth", telemetry.ground_truth())
    north_m = math.radians(landed.latitude_deg - home.latitude_deg) * 6371000.0
    east_m = math.radians(landed.longitude_deg - home.longitude_deg) * 6371000.0 * math.cos(math.radians(HOME_LAT_DEG))
    assert math.hypot(north_m, east_m) < 2.0  # check_home_within(2.0)
