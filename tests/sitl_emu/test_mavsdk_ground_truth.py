"""Conformance: MAVSDK's ground truth (Telemetry.set_rate_ground_truth / ground_truth), what PX4's own SITL test
harness asks first (test/mavsdk_tests/autopilot_tester.cpp store_home: set_rate_ground_truth(15), then the ground
truth's latitude and longitude as home). PX4 serves it as HIL_STATE_QUATERNION from SIH's groundtruth topics."""

from __future__ import annotations

import asyncio
import math
from typing import Any

import pytest
from support.mavsdk_waits import Session, connect
from support.serve_process import load_mavsdk

HOME_LAT_DEG, HOME_LON_DEG = 47.397742, 8.545594  # SIH_LOC_LAT0 / SIH_LOC_LON0


@pytest.mark.timeout(120)
def test_mavsdk_ground_truth_is_served_at_the_rate_it_sets(mavsdk_port: int) -> None:
    mavsdk_asyncio = load_mavsdk()
    session = Session()
    try:
        asyncio.run(asyncio.wait_for(_ground_truth(mavsdk_asyncio, mavsdk_port, session), timeout=100))
    finally:
        print("\nMAVSDK calls and outcomes:\n" + session.table())


async def _ground_truth(mavsdk_asyncio: Any, port: int, s: Session) -> None:
    from mavsdk.asyncio.plugins.telemetry import TelemetryAsync

    config = mavsdk_asyncio.Configuration.create_with_component_type(mavsdk_asyncio.ComponentType.GROUND_STATION)
    async with mavsdk_asyncio.Mavsdk(config) as mavsdk:
        telemetry = TelemetryAsync(await connect(mavsdk, port, s))
        await s.call("Telemetry.set_rate_ground_truth(15)", telemetry.set_rate_ground_truth(15.0))
        home = await s.wait_for("a finite ground truth", telemetry.ground_truth,
                                lambda g: math.isfinite(g.latitude_deg) and math.isfinite(g.longitude_deg),
                                timeout_s=10)
        assert home.latitude_deg == pytest.approx(HOME_LAT_DEG, abs=1e-6)
        assert home.longitude_deg == pytest.approx(HOME_LON_DEG, abs=1e-6)
        assert 480.0 < home.absolute_altitude_m < 500.0  # AMSL on the ground at SIH_LOC_H0
