"""DO_LAND_START as a mission item on the wire (src/modules/mavlink/mavlink_mission.cpp parse_mavlink_mission_item /
format_mavlink_mission_item with PX4 main's mavlink_command_params.hpp, which lets the marker carry params 5-7), and
QGroundControl's landing pattern (src/MissionManager/LandingComplexItem.cc appendMissionItems)."""

from __future__ import annotations

import math

import pytest
from support.handler_ctx import Client, FakeVehicle, MemoryContext
from support.mission_wire import LAT, LON, download, item, upload

from sitl_emu.mavlink.protocols.mission import MissionProtocol
from sitl_emu.mavlink.protocols.mission_items import MAV_MISSION_ACCEPTED

TAKEOFF, LAND, LOITER_TO_ALT, LAND_START = 22, 21, 31, 189
MAV_MISSION_INVALID_PARAM1 = 6


@pytest.fixture()
def setup() -> tuple[MissionProtocol, MemoryContext, Client]:
    return MissionProtocol(), MemoryContext(FakeVehicle()), Client()


def test_a_land_start_marker_in_a_global_frame_is_stored_with_its_position(setup):
    """In a global frame: accepted, kept as a global item with its position and no param, downloaded in its frame
    (the INT or the float flavour)."""
    proto, ctx, client = setup
    marker = item(client, 1, LAND_START, x=LAT + 3000, y=LON - 2000, params=(0, 0, 0, math.nan), z=12.0)
    items = [item(client, 0, TAKEOFF), marker, item(client, 2, LAND, z=0.0)]
    assert upload(proto, ctx, client, items) == MAV_MISSION_ACCEPTED
    got = download(proto, ctx, client)[1]
    assert (got.command, got.frame, got.x, got.y, got.z) == (LAND_START, 6, LAT + 3000, LON - 2000, 12.0)
    assert (got.param1, got.param2, got.param3, got.param4) == (0, 0, 0, 0)
    legacy = download(proto, ctx, client, legacy=True)[1]
    assert legacy.frame == 3 and legacy.x == pytest.approx((LAT + 3000) * 1e-7)


def test_a_land_start_marker_takes_no_other_param(setup):
    proto, ctx, client = setup
    refused = item(client, 1, LAND_START, params=(2.0, 0, 0, 0))
    assert upload(proto, ctx, client, [item(client, 0, TAKEOFF), refused]) == MAV_MISSION_INVALID_PARAM1


def test_qgroundcontrol_s_landing_pattern_uploads(setup):
    """DO_LAND_START in MAV_FRAME_MISSION with seven zeros, the final approach (LOITER_TO_ALT: heading required, the
    signed loiter radius, 0, exit on the tangent), the land item; downloaded as sent."""
    proto, ctx, client = setup
    pattern = [item(client, 0, TAKEOFF), item(client, 1, LAND_START, frame=2, x=0, y=0, params=(0, 0, 0, 0), z=0.0),
               item(client, 2, LOITER_TO_ALT, x=LAT + 3000, params=(1.0, -75.0, 0.0, 1.0), z=20.0),
               item(client, 3, LAND, params=(0, 0, 0, math.nan), z=0.0)]
    assert upload(proto, ctx, client, pattern) == MAV_MISSION_ACCEPTED
    got = download(proto, ctx, client)
    assert [(m.command, m.frame) for m in got] == [(TAKEOFF, 6), (LAND_START, 2), (LOITER_TO_ALT, 6), (LAND, 6)]
    assert (got[2].param1, got[2].param2, got[2].param4) == (1.0, -75.0, 1.0)
