"""Return around the geofence on a Vehicle (no MAVLink): PX4's case "Return direct with geofence obstruction"
(test/mavsdk_tests/test_multicopter_rtl_with_geofence.cpp) step by step: its plan moved here, GF_ACTION 1 (warn),
RTL_TYPE 0, the mission started, Return when the mission reaches item 3; the vehicle's true position never breaks a
fence shape, and it lands within 5 m of home. Its MAVSDK replay: tests/sitl_emu/test_mavsdk_rtl_geofence.py."""

from __future__ import annotations

import math

import pytest
from support.geofence_avoid_plan import RTL_AT_SEQ, BreachMonitor, plan_here

from sitl_emu.navigator.mission_store import PLAN_FENCE, PLAN_MISSION
from sitl_emu.px4 import MavCmd, MavResult, NavState
from sitl_emu.types import VehicleCommand
from sitl_emu.vehicle.vehicle import Vehicle

pytestmark = pytest.mark.slow  # about 4 simulated minutes


def _command(v: Vehicle, cmd: int, *params: float) -> int:
    ack = v.handle_command(VehicleCommand(cmd, (*params, *([math.nan] * (7 - len(params))))))
    assert ack is not None
    return ack.result


def test_return_goes_around_the_exclusion_polygon_and_lands_home() -> None:
    v = Vehicle()
    v.params.set("GF_ACTION", 1)
    v.params.set("RTL_TYPE", 0)
    plan = plan_here(v.ref.lat_deg, v.ref.lon_deg)
    store = v.mission_store()
    store.replace(PLAN_MISSION, plan.mission)
    store.replace(PLAN_FENCE, plan.fence)
    monitor = BreachMonitor(plan.fence, v.ref)
    v.run_for(3.0)
    assert _command(v, MavCmd.COMPONENT_ARM_DISARM, 1, 0) == MavResult.ACCEPTED
    v.run_for(1.0)
    assert _command(v, MavCmd.MISSION_START, 0, 0) == MavResult.ACCEPTED
    seen = v.last_event_seq
    texts: list[str] = []
    end_us = v.time_us + 400_000_000
    while v.time_us < end_us and v.snapshot().armed:
        v.step()
        n, e, _ = v.ground_truth().pos_ned_m
        monitor.check(n, e)
        if store.current_seq == RTL_AT_SEQ and v.snapshot().nav_state is NavState.AUTO_MISSION:
            assert _command(v, MavCmd.DO_SET_MODE, 1, 4, 5) == MavResult.ACCEPTED  # AUTO.RTL (MAVSDK's return)
    for event in v.events_after(seen):
        texts.append(event.text)
    assert not v.snapshot().armed, f"not landed in 400 s: {texts}"
    assert monitor.breach is None, f"fence breached at {monitor.breach}"
    assert "RTL: avoiding geofence" in texts
    n, e, _ = v.ground_truth().pos_ned_m
    assert math.hypot(n, e) < 5.0  # check_home_within(5.0)
