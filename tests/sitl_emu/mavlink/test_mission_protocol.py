"""Mission protocol for an empty plan: QGC's download completes, uploads are refused at once (reference 9c.4)."""

from __future__ import annotations

import pytest
from support import REPO_ROOT
from support.handler_ctx import CLIENT_COMPID, CLIENT_SYSID, Client, FakeVehicle, MemoryContext

from sitl_emu.mavlink.mission_protocol import (
    MAV_MISSION_ACCEPTED,
    MAV_MISSION_ERROR,
    MAV_MISSION_UNSUPPORTED,
    MissionProtocol,
)
from sitl_emu.px4 import Severity


@pytest.fixture()
def setup() -> tuple[MissionProtocol, MemoryContext, Client]:
    return MissionProtocol(), MemoryContext(FakeVehicle()), Client()


@pytest.mark.parametrize("mission_type", [0, 1, 2])
def test_download_of_every_plan_type_is_an_empty_count(setup, mission_type):
    proto, ctx, client = setup
    proto.handle(client.msg("MISSION_REQUEST_LIST", 1, 1, mission_type), ctx)
    (count,) = ctx.take()
    assert count.get_type() == "MISSION_COUNT"
    assert (count.count, count.mission_type) == (0, mission_type)
    assert (count.target_system, count.target_component) == (CLIENT_SYSID, CLIENT_COMPID)
    # the GCS closes the transfer with an ACK; nothing more is sent
    proto.handle(client.msg("MISSION_ACK", 1, 1, 0, mission_type), ctx)
    proto.tick(ctx)
    assert ctx.take() == []


def test_request_list_for_another_system_is_ignored(setup):
    proto, ctx, client = setup
    proto.handle(client.msg("MISSION_REQUEST_LIST", 2, 1, 0), ctx)
    proto.handle(client.msg("MISSION_REQUEST_LIST", 0, 1, 0), ctx)
    assert ctx.take() == []


def test_mission_planner_compid_is_accepted(setup):
    proto, ctx, client = setup
    proto.handle(client.msg("MISSION_REQUEST_LIST", 1, 190, 0), ctx)
    assert [m.get_type() for m in ctx.take()] == ["MISSION_COUNT"]


@pytest.mark.parametrize("mission_type", [0, 1, 2])
def test_clear_all_is_accepted(setup, mission_type):
    proto, ctx, client = setup
    proto.handle(client.msg("MISSION_CLEAR_ALL", 1, 1, mission_type), ctx)
    (ack,) = ctx.take()
    assert ack.get_type() == "MISSION_ACK"
    assert (ack.type, ack.mission_type) == (MAV_MISSION_ACCEPTED, mission_type)


def test_empty_upload_is_accepted(setup):
    proto, ctx, client = setup
    proto.handle(client.msg("MISSION_COUNT", 1, 1, 0, 0), ctx)
    (ack,) = ctx.take()
    assert ack.type == MAV_MISSION_ACCEPTED


def test_upload_is_refused_at_once_and_reported(setup):
    proto, ctx, client = setup
    proto.handle(client.msg("MISSION_COUNT", 1, 1, 5, 0), ctx)
    (ack,) = ctx.take()
    assert ack.get_type() == "MISSION_ACK"
    assert (ack.type, ack.mission_type) == (MAV_MISSION_UNSUPPORTED, 0)
    assert (ack.target_system, ack.target_component) == (CLIENT_SYSID, CLIENT_COMPID)
    (event,) = ctx.vehicle.events
    assert event.severity == Severity.CRITICAL
    assert "not supported yet" in event.text
    proto.tick(ctx)
    assert ctx.take() == []  # never requests items


def test_geofence_upload_is_refused_with_its_type(setup):
    proto, ctx, client = setup
    proto.handle(client.msg("MISSION_COUNT", 1, 1, 3, 1), ctx)
    (ack,) = ctx.take()
    assert (ack.type, ack.mission_type) == (MAV_MISSION_UNSUPPORTED, 1)
    assert "Geofence" in ctx.vehicle.events[0].text


def test_item_without_transfer_is_an_error(setup):
    proto, ctx, client = setup
    item = client.msg("MISSION_ITEM_INT", 1, 1, 0, 6, 16, 0, 1, 0, 0, 0, 0, 473977420, 85455940, 10.0, 0)
    proto.handle(item, ctx)
    (ack,) = ctx.take()
    assert ack.type == MAV_MISSION_ERROR


def test_item_request_without_transfer_is_ignored(setup):
    proto, ctx, client = setup
    proto.handle(client.msg("MISSION_REQUEST_INT", 1, 1, 0, 0), ctx)
    assert ctx.take() == []


def test_readme_says_what_the_mission_protocol_does(setup):
    """The README promised "the mission protocol" while uploads were refused (issue 10.5): it must say what happens."""

    proto, ctx, client = setup
    proto.handle(client.msg("MISSION_COUNT", 1, 1, 3, 0), ctx)
    (ack,) = [m for m in ctx.take() if m.get_type() == "MISSION_ACK"]
    readme = " ".join((REPO_ROOT / "README.md").read_text().split())
    assert "mission protocols" not in readme
    if ack.type == MAV_MISSION_UNSUPPORTED:
        assert "a mission upload is refused at once with MISSION_ACK `MAV_MISSION_UNSUPPORTED`" in readme
