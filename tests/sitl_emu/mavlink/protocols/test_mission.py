"""The mission protocol handler in memory (src/modules/mavlink/mavlink_mission.cpp): uploads, downloads, clearing,
the current item, PX4's item checks, retries, timeout and the one-upload-at-a-time lock, for the three plan types.
The reference's recorded cases run over loopback UDP in test_mission_cases.py."""

from __future__ import annotations

import math

import pytest
from support import REPO_ROOT
from support.handler_ctx import CLIENT_COMPID, CLIENT_SYSID, Client, FakeVehicle, MemoryContext
from support.mission_wire import LAT, LON, download, item, upload

from sitl_emu.mavlink.protocols.command_params import unused_param_result
from sitl_emu.mavlink.protocols.mission import MissionProtocol
from sitl_emu.mavlink.protocols.mission_items import (
    MAV_MISSION_ACCEPTED,
    MAV_MISSION_ERROR,
    MAV_MISSION_INVALID_PARAM5_X,
    MAV_MISSION_NO_SPACE,
    MAV_MISSION_UNSUPPORTED,
    MAV_MISSION_UNSUPPORTED_FRAME,
    UINT16_MAX,
    mission_current_fields,
)
from sitl_emu.navigator.mission_store import MAX_ITEMS
from sitl_emu.px4 import NavState, Severity

WAYPOINT, TAKEOFF, RTL, FENCE_POLY_IN, FENCE_CIRCLE_IN, RALLY = 16, 22, 20, 5001, 5003, 5100
MAV_MISSION_INVALID_PARAM1, MAV_MISSION_INVALID_PARAM2 = 6, 7  # common.xml
MAV_MISSION_INVALID_PARAM3, MAV_MISSION_INVALID_PARAM4 = 8, 9
MAV_MISSION_INVALID_PARAM7 = 12
INT32_MAX = 2**31 - 1  # MISSION_ITEM_INT's "no value" in x, y


@pytest.fixture()
def setup() -> tuple[MissionProtocol, MemoryContext, Client]:
    return MissionProtocol(), MemoryContext(FakeVehicle()), Client()


def texts(ctx: MemoryContext) -> list[str]:
    return [e.text for e in ctx.vehicle.events]


@pytest.mark.parametrize("mission_type", [0, 1, 2])
def test_download_of_an_empty_plan_is_a_count_of_zero(setup, mission_type):
    proto, ctx, client = setup
    assert download(proto, ctx, client, mission_type) == []
    ctx.advance(6_000_000)
    proto.tick(ctx)
    assert ctx.take() == [] and ctx.vehicle.events == []  # the ACK closed it: no retry, no timeout


def test_mission_upload_is_stored_and_downloaded_with_the_current_item(setup):
    proto, ctx, client = setup
    items = [item(client, 0, TAKEOFF), item(client, 1, x=LAT + 1000), item(client, 2, x=LAT + 2000),
             item(client, 3, RTL, frame=2, x=0, y=0, params=(0, 0, 0, 0), z=0.0)]
    assert upload(proto, ctx, client, items) == MAV_MISSION_ACCEPTED
    got = download(proto, ctx, client)
    assert [(m.seq, m.command, m.frame, m.x, m.current) for m in got] == [
        (0, TAKEOFF, 6, LAT, 1), (1, WAYPOINT, 6, LAT + 1000, 0), (2, WAYPOINT, 6, LAT + 2000, 0), (3, RTL, 2, 0, 0)]
    assert all((m.target_system, m.target_component) == (CLIENT_SYSID, CLIENT_COMPID) for m in got)
    assert math.isnan(got[1].param4)
    store = ctx.vehicle.mission_store()
    assert mission_current_fields(store, NavState.AUTO_LOITER) == (0, 4, 2, 2)  # NOT_STARTED, suspended


def test_empty_mission_reports_no_mission():
    store = FakeVehicle().mission_store()
    assert mission_current_fields(store, NavState.AUTO_MISSION) == (0, UINT16_MAX, 1, 1)


def test_legacy_float_upload_and_download(setup):
    proto, ctx, client = setup
    proto.handle(client.msg("MISSION_COUNT", 1, 1, 1, 0), ctx)
    proto.handle(client.msg("MISSION_ITEM", 1, 1, 0, 3, WAYPOINT, 0, 1, 0, 0, 0, 0, 47.397742, 8.545594, 7.0, 0), ctx)
    assert [m.get_type() for m in ctx.take()] == ["MISSION_REQUEST_INT", "MISSION_ACK"]
    (got,) = download(proto, ctx, client, legacy=True)
    assert got.get_type() == "MISSION_ITEM" and got.frame == 3  # float flavour: GLOBAL_RELATIVE_ALT
    assert (got.x, got.y, got.z) == (pytest.approx(47.397742), pytest.approx(8.545594), 7.0)


def test_download_keeps_only_the_params_px4_keeps(setup):
    proto, ctx, client = setup
    assert upload(proto, ctx, client, [item(client, 0, params=(2.0, 3.0, math.nan, -90.0))]) == MAV_MISSION_ACCEPTED
    (got,) = download(proto, ctx, client)
    assert (got.param1, got.param2, got.param3, got.param4) == (2.0, 3.0, 0.0, pytest.approx(270.0))


@pytest.mark.parametrize(("kwargs", "result"), [
    ({"command": 31010}, MAV_MISSION_UNSUPPORTED),
    ({"command": RTL, "params": (0, 0, 0, 0), "x": INT32_MAX, "y": INT32_MAX, "z": 0.0}, MAV_MISSION_UNSUPPORTED),
    ({"command": RTL, "params": (0, 0, 0, 0), "z": 0.0}, MAV_MISSION_INVALID_PARAM5_X),  # RTL has no position
    ({"params": (0, 0, 2.0, math.nan)}, MAV_MISSION_INVALID_PARAM3),  # PX4 flies no pass radius
    ({"command": TAKEOFF, "params": (-1.0, 3.0, 0, 0)}, MAV_MISSION_INVALID_PARAM2),  # param1 -1: QGC's pitch
    ({"frame": 2, "command": RTL, "params": (0, 0, 0, 0), "x": 0, "y": 0}, MAV_MISSION_INVALID_PARAM7),
    ({"frame": 2, "command": 178, "params": (1, 5, -1, 7.0), "z": 0.0}, MAV_MISSION_INVALID_PARAM4),  # speed
    ({"frame": 10}, MAV_MISSION_UNSUPPORTED_FRAME),  # terrain frame
    ({"frame": 1}, MAV_MISSION_UNSUPPORTED_FRAME),  # local NED
    ({"command": RTL, "x": 0, "y": 0, "params": (0, 0, 0, 0), "z": 0.0}, MAV_MISSION_INVALID_PARAM5_X),
    ({"frame": 2, "command": 31010}, MAV_MISSION_UNSUPPORTED),
])
def test_invalid_item_ends_the_upload_and_keeps_the_stored_plan(setup, kwargs, result):
    proto, ctx, client = setup
    assert upload(proto, ctx, client, [item(client, 0)]) == MAV_MISSION_ACCEPTED
    assert upload(proto, ctx, client, [item(client, 0, TAKEOFF), item(client, 1, **kwargs)]) == result
    assert texts(ctx) == ["IGN MISSION_ITEM: Invalid item"]
    assert ctx.vehicle.events[0].severity == Severity.CRITICAL and ctx.vehicle.events[0].is_event
    assert [m.command for m in download(proto, ctx, client)] == [WAYPOINT]  # never half-written


@pytest.mark.parametrize(("x", "result"), [(0, MAV_MISSION_ACCEPTED), (-(2**31), MAV_MISSION_ACCEPTED),
                                           (INT32_MAX, MAV_MISSION_ACCEPTED), (7, MAV_MISSION_INVALID_PARAM5_X)])
def test_an_item_without_position_takes_0_or_the_int32_sentinels_in_x(setup, x, result):
    """mavlink_command_params.hpp: QGroundControl's camera items come in MAV_FRAME_MISSION with x, y INT32_MIN (a
    NaN as int32; PR 28079 accepts it), its RTL with 0; any other value where the command has no param5 is refused."""
    proto, ctx, client = setup
    stop = item(client, 1, 2001, frame=2, x=x, y=x, params=(0, math.nan, math.nan, math.nan), z=math.nan)
    assert upload(proto, ctx, client, [item(client, 0, TAKEOFF), stop]) == result


def test_a_fence_circle_at_0_0_with_radius_0_is_stored(setup):
    """MAVSDK-Python's geofence example uploads such a placeholder circle; a fence circle uses x and y, so PX4 stores
    it (px4-recorded-facts.md section 4) where an RTL item at 0, 0 is refused."""
    proto, ctx, client = setup
    circle = item(client, 0, FENCE_CIRCLE_IN, mission_type=1, x=0, y=0, params=(0, 0, 0, 0), z=0.0)
    assert upload(proto, ctx, client, [circle], 1) == MAV_MISSION_ACCEPTED
    assert [(m.command, m.x, m.y) for m in download(proto, ctx, client, 1)] == [(FENCE_CIRCLE_IN, 0, 0)]


def test_a_land_start_marker_may_carry_a_position_but_no_other_param():
    """mavlink_command_params.hpp: DO_LAND_START takes params 5-7 (an optional marker position, which QGroundControl
    sets) and none of 1-4."""
    assert unused_param_result(189, (0, 0, 0, 0), LAT, LON, 10.0, int_position=True) is None
    assert unused_param_result(189, (3.0, 0, 0, 0), LAT, LON, 10.0, int_position=True) == MAV_MISSION_INVALID_PARAM1


def test_too_many_items_is_no_space(setup):
    proto, ctx, client = setup
    proto.handle(client.msg("MISSION_COUNT", 1, 1, MAX_ITEMS[2] + 1, 2), ctx)
    (ack,) = ctx.take()
    assert (ack.type, ack.mission_type) == (MAV_MISSION_NO_SPACE, 2)


def test_count_zero_clears_the_plan(setup):
    proto, ctx, client = setup
    upload(proto, ctx, client, [item(client, 0)])
    assert upload(proto, ctx, client, []) == MAV_MISSION_ACCEPTED
    assert download(proto, ctx, client) == []


def test_fence_and_rally_plans_are_stored_apart(setup):
    proto, ctx, client = setup
    fence = [item(client, i, FENCE_POLY_IN, mission_type=1, x=LAT + i * 100, params=(3, 0, 0, 0), z=0.0)
             for i in range(3)]
    assert upload(proto, ctx, client, fence, 1) == MAV_MISSION_ACCEPTED
    assert upload(proto, ctx, client, [item(client, 0, RALLY, mission_type=2)], 2) == MAV_MISSION_ACCEPTED
    assert [m.command for m in download(proto, ctx, client, 1)] == [FENCE_POLY_IN] * 3
    assert [(m.command, m.mission_type, m.current) for m in download(proto, ctx, client, 2)] == [(RALLY, 2, 1)]
    assert download(proto, ctx, client, 0) == []
    proto.handle(client.msg("MISSION_CLEAR_ALL", 1, 1, 1), ctx)
    assert [m.type for m in ctx.take()] == [MAV_MISSION_ACCEPTED]
    assert download(proto, ctx, client, 1) == [] and len(download(proto, ctx, client, 2)) == 1
    proto.handle(client.msg("MISSION_CLEAR_ALL", 1, 1, 255), ctx)
    ctx.take()
    assert download(proto, ctx, client, 2) == []


def test_plan_checks_refuse_a_fence_item_in_a_mission_and_a_short_polygon(setup):
    proto, ctx, client = setup
    assert upload(proto, ctx, client, [item(client, 0, FENCE_CIRCLE_IN, z=0.0)]) == MAV_MISSION_ERROR
    short = [item(client, 0, FENCE_POLY_IN, mission_type=1, params=(2, 0, 0, 0), z=0.0)]
    assert upload(proto, ctx, client, short, 1) == MAV_MISSION_ERROR


def test_out_of_sequence_item_is_dropped_and_the_request_repeated_then_the_transfer_times_out(setup):
    proto, ctx, client = setup
    upload(proto, ctx, client, [item(client, 0)])
    proto.handle(client.msg("MISSION_COUNT", 1, 1, 2, 0), ctx)
    proto.handle(item(client, 1), ctx)
    assert [m.seq for m in ctx.take()] == [0]
    requests = 0
    for _ in range(5200 // 4):
        ctx.advance(4000)
        proto.tick(ctx)
        requests += len(ctx.take("MISSION_REQUEST_INT"))
    assert 19 <= requests <= 20
    assert texts(ctx) == ["Mission sync timeout"]
    assert ctx.take() == []  # no MISSION_ACK
    assert [m.command for m in download(proto, ctx, client)] == [WAYPOINT]  # the old plan
    assert upload(proto, ctx, client, [item(client, 0)]) == MAV_MISSION_ACCEPTED  # the lock was released


def test_lost_request_is_asked_again_on_a_repeated_count(setup):
    proto, ctx, client = setup
    proto.handle(client.msg("MISSION_COUNT", 1, 1, 2, 0), ctx)
    proto.handle(client.msg("MISSION_COUNT", 1, 1, 2, 0), ctx)
    assert [(m.get_type(), m.seq) for m in ctx.take()] == [("MISSION_REQUEST_INT", 0)] * 2
    proto.handle(item(client, 0), ctx)
    proto.handle(client.msg("MISSION_COUNT", 1, 1, 2, 0), ctx)
    assert [m.get_type() for m in ctx.take()] == ["MISSION_REQUEST_INT", "MISSION_ACK"]
    assert texts(ctx) == ["WPM: REJ. CMD: Busy"]


def test_one_upload_at_a_time_across_links(setup):
    proto, ctx, client = setup
    other_ctx = MemoryContext(ctx.vehicle, link_name="gcs")
    other, other_client = MissionProtocol(), Client(sysid=254)
    proto.handle(client.msg("MISSION_COUNT", 1, 1, 1, 0), ctx)
    other.handle(other_client.msg("MISSION_COUNT", 1, 1, 1, 0), other_ctx)
    (ack,) = other_ctx.take()
    assert (ack.type, ack.target_system) == (MAV_MISSION_ERROR, 254)
    proto.handle(item(client, 0), ctx)
    assert upload(other, other_ctx, other_client, [item(other_client, 0, TAKEOFF)]) == MAV_MISSION_ACCEPTED


def test_another_client_during_an_upload_is_refused(setup):
    proto, ctx, client = setup
    stranger = Client(sysid=200)
    proto.handle(client.msg("MISSION_COUNT", 1, 1, 2, 0), ctx)
    ctx.take()
    proto.handle(stranger.msg("MISSION_COUNT", 1, 1, 1, 0), ctx)
    proto.handle(item(stranger, 0), ctx)
    assert [(m.type, m.target_system) for m in ctx.take()] == [(MAV_MISSION_ERROR, 200)]
    assert texts(ctx) == ["REJ. MIS ITEM: partner id mismatch"]


def test_item_outside_a_transfer(setup):
    proto, ctx, client = setup
    proto.handle(item(client, 5), ctx)  # no transfer partner yet: PX4 only complains
    assert ctx.take() == [] and texts(ctx) == ["REJ. MIS ITEM: partner id mismatch"]
    download(proto, ctx, client)
    proto.handle(item(client, 5), ctx)
    (ack,) = ctx.take()
    assert ack.type == MAV_MISSION_ERROR and texts(ctx)[-1] == "IGN MISSION_ITEM: No transfer"


def test_last_item_again_after_the_final_ack_is_acknowledged_again(setup):
    proto, ctx, client = setup
    last = item(client, 0)
    upload(proto, ctx, client, [last])
    proto.handle(last, ctx)
    assert [m.type for m in ctx.take()] == [MAV_MISSION_ACCEPTED]


def test_request_without_transfer_is_ignored(setup):
    proto, ctx, client = setup
    download(proto, ctx, client)
    proto.handle(client.msg("MISSION_REQUEST_INT", 1, 1, 0, 0), ctx)
    assert ctx.take() == []


def test_unexpected_request_aborts_the_download(setup):
    proto, ctx, client = setup
    upload(proto, ctx, client, [item(client, 0), item(client, 1)])
    proto.handle(client.msg("MISSION_REQUEST_LIST", 1, 1, 0), ctx)
    proto.handle(client.msg("MISSION_REQUEST_INT", 1, 1, 1, 0), ctx)
    assert [m.get_type() for m in ctx.take()] == ["MISSION_COUNT", "MISSION_ACK"]
    assert texts(ctx) == ["WPM: REJ. CMD: Req. WP was unexpected"]


def test_unanswered_count_is_repeated_then_times_out(setup):
    proto, ctx, client = setup
    proto.handle(client.msg("MISSION_REQUEST_LIST", 1, 1, 0), ctx)
    counts = 0
    for _ in range(5100 // 4):
        ctx.advance(4000)
        proto.tick(ctx)
        counts += len(ctx.take("MISSION_COUNT"))
    assert counts >= 15 and texts(ctx) == ["Mission sync timeout"]


def test_set_current(setup):
    proto, ctx, client = setup
    upload(proto, ctx, client, [item(client, 0), item(client, 1)])
    proto.tick(ctx)
    ctx.take()
    proto.handle(client.msg("MISSION_SET_CURRENT", 1, 1, 1), ctx)
    proto.tick(ctx)  # the new current item is reported at the link's next pass
    (current,) = ctx.take("MISSION_CURRENT")
    assert (current.seq, current.total) == (1, 2)
    assert [m.current for m in download(proto, ctx, client)] == [0, 1]
    proto.handle(client.msg("MISSION_SET_CURRENT", 1, 1, 2), ctx)
    assert texts(ctx) == ["WPM: WP CURR CMD: Not in list"]


def test_upload_marks_the_mission_parameters_used(setup):
    proto, ctx, client = setup
    params = ctx.vehicle.params
    assert params.index_of("MIS_DIST_1WP") == -1
    upload(proto, ctx, client, [item(client, 0)])
    assert params.index_of("MIS_DIST_1WP") >= 0 and params.index_of("MIS_TKO_LAND_REQ") >= 0


def test_messages_for_another_system_are_ignored(setup):
    proto, ctx, client = setup
    proto.handle(client.msg("MISSION_REQUEST_LIST", 2, 1, 0), ctx)
    proto.handle(client.msg("MISSION_COUNT", 0, 1, 1, 0), ctx)
    assert ctx.take() == []
    proto.handle(client.msg("MISSION_REQUEST_LIST", 1, 190, 0), ctx)  # the mission planner's compid is accepted
    assert [m.get_type() for m in ctx.take()] == ["MISSION_COUNT"]


def test_readme_says_what_the_mission_protocol_does():
    readme = " ".join((REPO_ROOT / "README.md").read_text().split())
    assert "upload is refused at once" not in readme
    assert "plans upload, download and clear over PX4's mission protocol" in readme


def test_busy_answers_while_a_transfer_runs(setup):
    proto, ctx, client = setup
    upload(proto, ctx, client, [item(client, 0), item(client, 1)])
    proto.handle(client.msg("MISSION_REQUEST_LIST", 1, 1, 0), ctx)  # a download is running
    proto.handle(client.msg("MISSION_REQUEST_LIST", 1, 1, 1), ctx)
    proto.handle(client.msg("MISSION_COUNT", 1, 1, 1, 0), ctx)
    proto.handle(client.msg("MISSION_CLEAR_ALL", 1, 1, 0), ctx)
    proto.handle(client.msg("MISSION_SET_CURRENT", 1, 1, 1), ctx)
    assert [m.get_type() for m in ctx.take()] == ["MISSION_COUNT", "MISSION_ACK"]
    assert texts(ctx) == ["Mission download request ignored, already active", "WPM: IGN MISSION_COUNT: Busy",
                          "WPM: IGN CLEAR CMD: Busy", "WPM: IGN WP CURR CMD: Busy"]
    assert ctx.vehicle.events[0].severity == Severity.INFO
    assert ctx.vehicle.mission_store().count(0) == 2 and ctx.vehicle.mission_store().current_seq == 0


def test_the_largest_mission_is_stored_and_one_more_item_is_no_space(setup):
    proto, ctx, client = setup
    limit = MAX_ITEMS[0]
    proto.handle(client.msg("MISSION_COUNT", 1, 1, limit + 1, 0), ctx)
    assert [m.type for m in ctx.take()] == [MAV_MISSION_NO_SPACE]
    wp = item(client, 0)
    proto.handle(client.msg("MISSION_COUNT", 1, 1, limit, 0), ctx)
    for seq in range(limit):
        (request,) = ctx.take()
        assert request.seq == seq
        wp.seq = seq
        proto.handle(wp, ctx)
    assert [m.type for m in ctx.take()] == [MAV_MISSION_ACCEPTED]
    assert ctx.vehicle.mission_store().count(0) == limit == 10_000


def test_progress_current_on_change_and_reached_repeated_ten_times(setup):
    """MavlinkMissionManager::send: MISSION_CURRENT when the navigator's current item changes, MISSION_ITEM_REACHED
    at once and then again once a second, 10 times."""
    proto, ctx, client = setup
    upload(proto, ctx, client, [item(client, 0), item(client, 1)])
    proto.tick(ctx)
    ctx.take()
    store = ctx.vehicle.mission_store()
    store.current_seq, store.seq_reached = 1, 0
    proto.tick(ctx)
    assert [(m.get_type(), m.seq) for m in ctx.take()] == [("MISSION_CURRENT", 1), ("MISSION_ITEM_REACHED", 0)]
    later = []
    for _ in range(15 * 250):
        ctx.advance(4000)
        proto.tick(ctx)
        later += [(m.get_type(), m.seq) for m in ctx.take()]
    assert later == [("MISSION_ITEM_REACHED", 0)] * 10
