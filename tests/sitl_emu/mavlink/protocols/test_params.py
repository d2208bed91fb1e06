"""PARAM protocol as PX4 speaks it (px4-behaviour.md section 10), with real pymavlink messages in and out."""

from __future__ import annotations

import math
import struct

import pytest
from support.handler_ctx import Client, FakeVehicle, MemoryContext

from sitl_emu.mavlink.protocols.params import (
    HASH_CHECK_INDEX,
    MAV_PARAM_TYPE_INT32,
    MAV_PARAM_TYPE_REAL32,
    MAV_PARAM_TYPE_UINT32,
    PARAM_ERROR_DOES_NOT_EXIST,
    PARAM_ERROR_READ_ONLY,
    PARAM_ERROR_TYPE_MISMATCH,
    PARAM_ERROR_TYPE_UNSUPPORTED,
    PARAM_ERROR_VALUE_OUT_OF_RANGE,
    PARAMS_PER_TICK,
    UNUSED_INDEX,
    ParamProtocol,
    float_bits_to_int32,
    int32_to_float_bits,
)
from sitl_emu.px4 import Severity


@pytest.fixture()
def setup() -> tuple[ParamProtocol, MemoryContext, Client]:
    vehicle = FakeVehicle()
    ctx = MemoryContext(vehicle)
    proto = ParamProtocol()
    proto.tick(ctx)  # first tick: takes the registry as its baseline, sends nothing
    return proto, ctx, Client()


def _set(client: Client, name: str, value: float, type_code: int, target: int = 1) -> object:
    return client.msg("PARAM_SET", target, 1, name.encode(), value, type_code)


def _drain(proto: ParamProtocol, ctx: MemoryContext, ticks: int = 1000) -> list:
    out = []
    for _ in range(ticks):
        proto.tick(ctx)
        got = ctx.take("PARAM_VALUE")
        if not got:
            break
        out.extend(got)
    return out


def test_request_list_sends_hash_then_every_param_in_order(setup):
    proto, ctx, client = setup
    registry = ctx.vehicle.params
    proto.handle(client.msg("PARAM_REQUEST_LIST", 1, 1), ctx)
    values = _drain(proto, ctx)
    assert values[0].param_id == "_HASH_CHECK"
    assert values[0].param_index == HASH_CHECK_INDEX
    assert values[0].param_type == MAV_PARAM_TYPE_UINT32
    assert struct.unpack("<I", struct.pack("<f", values[0].param_value))[0] == registry.hash_check()
    rest = values[1:]
    assert [m.param_index for m in rest] == list(range(len(registry)))
    assert [m.param_id for m in rest] == [registry.name_at(i) for i in range(len(registry))]
    assert all(m.param_count == len(registry) for m in values)


def test_request_list_streams_at_most_20_per_tick(setup):
    proto, ctx, client = setup
    proto.handle(client.msg("PARAM_REQUEST_LIST", 1, 0), ctx)
    proto.tick(ctx)
    assert len(ctx.take("PARAM_VALUE")) == PARAMS_PER_TICK


def test_request_list_needs_exact_sysid(setup):
    proto, ctx, client = setup
    proto.handle(client.msg("PARAM_REQUEST_LIST", 0, 0), ctx)  # broadcast sysid is not accepted by PX4
    proto.handle(client.msg("PARAM_REQUEST_LIST", 2, 1), ctx)
    proto.handle(client.msg("PARAM_REQUEST_LIST", 1, 5), ctx)
    assert _drain(proto, ctx) == []


def _error(ctx: MemoryContext) -> object:
    """The one message sent since the last take, which must be a PARAM_ERROR to the client (255/190)."""
    (err,) = ctx.take()
    assert err.get_type() == "PARAM_ERROR" and (err.target_system, err.target_component) == (255, 190)
    return err


def test_hash_check_set_stops_the_stream_and_answers_read_only(setup):
    proto, ctx, client = setup
    proto.handle(client.msg("PARAM_REQUEST_LIST", 1, 1), ctx)
    proto.tick(ctx)
    ctx.take()
    proto.handle(_set(client, "_HASH_CHECK", 0.0, MAV_PARAM_TYPE_UINT32), ctx)
    err = _error(ctx)  # PX4 main answers PARAM_ERROR READ_ONLY (px4-behaviour.md 10.4)
    assert (err.param_id, err.param_index, err.error) == ("_HASH_CHECK", -1, PARAM_ERROR_READ_ONLY)
    assert _drain(proto, ctx) == []


def test_hash_check_set_does_not_stop_the_stream_when_disabled(setup):
    proto, ctx, client = setup
    ctx.vehicle.params.set("MAV_HASH_CHK_EN", 0)
    proto.tick(ctx)
    ctx.take()
    proto.handle(client.msg("PARAM_REQUEST_LIST", 1, 1), ctx)
    proto.tick(ctx)
    ctx.take()
    proto.handle(_set(client, "_HASH_CHECK", 0.0, MAV_PARAM_TYPE_UINT32), ctx)
    assert len(_drain(proto, ctx)) == len(ctx.vehicle.params) + 1 - PARAMS_PER_TICK


def test_second_list_request_restarts_without_hash(setup):
    proto, ctx, client = setup
    proto.handle(client.msg("PARAM_REQUEST_LIST", 1, 1), ctx)
    proto.tick(ctx)
    ctx.take()
    proto.handle(client.msg("PARAM_REQUEST_LIST", 1, 1), ctx)
    values = _drain(proto, ctx)
    assert values[0].param_index == 0
    assert len(values) == len(ctx.vehicle.params)


def test_int32_values_travel_bytewise(setup):
    proto, ctx, client = setup
    proto.handle(client.msg("PARAM_REQUEST_READ", 1, 1, b"MAV_SYS_ID", -1), ctx)
    (msg,) = ctx.take("PARAM_VALUE")
    assert msg.param_type == MAV_PARAM_TYPE_INT32
    assert float_bits_to_int32(msg.param_value) == 1
    assert msg.param_value != 1.0  # the float field carries raw bytes (1.4e-45), not the number


def test_read_by_index_and_by_name(setup):
    proto, ctx, client = setup
    registry = ctx.vehicle.params
    index = registry.index_of("MIS_TAKEOFF_ALT") if "MIS_TAKEOFF_ALT" in registry else registry.index_of("BAT_LOW_THR")
    proto.handle(client.msg("PARAM_REQUEST_READ", 1, 1, b"", index), ctx)
    (by_index,) = ctx.take("PARAM_VALUE")
    assert by_index.param_index == index
    proto.handle(client.msg("PARAM_REQUEST_READ", 1, 1, by_index.param_id.encode(), -1), ctx)
    (by_name,) = ctx.take("PARAM_VALUE")
    assert by_name.param_index == index and by_name.param_type == MAV_PARAM_TYPE_REAL32


def test_read_hash_check_by_name(setup):
    proto, ctx, client = setup
    proto.handle(client.msg("PARAM_REQUEST_READ", 1, 1, b"_HASH_CHECK", -1), ctx)
    (msg,) = ctx.take("PARAM_VALUE")
    assert msg.param_id == "_HASH_CHECK" and msg.param_index == HASH_CHECK_INDEX


def test_unknown_name_or_index_read_gets_param_error_does_not_exist(setup):
    proto, ctx, client = setup
    proto.handle(client.msg("PARAM_REQUEST_READ", 1, 1, b"NO_SUCH_PARAM", -1), ctx)
    err = _error(ctx)
    assert (err.param_id, err.param_index, err.error) == ("NO_SUCH_PARAM", -1, PARAM_ERROR_DOES_NOT_EXIST)
    proto.handle(client.msg("PARAM_REQUEST_READ", 1, 1, b"", len(ctx.vehicle.params)), ctx)
    err = _error(ctx)
    assert (err.param_index, err.error) == (len(ctx.vehicle.params), PARAM_ERROR_DOES_NOT_EXIST)


def test_any_negative_index_reads_by_name(setup):
    proto, ctx, client = setup
    proto.handle(client.msg("PARAM_REQUEST_READ", 1, 1, b"MAV_SYS_ID", -7), ctx)
    (msg,) = ctx.take("PARAM_VALUE")
    assert msg.param_id == "MAV_SYS_ID" and msg.param_index == ctx.vehicle.params.index_of("MAV_SYS_ID")


def test_an_unused_parameter_is_read_and_set_by_name_only_and_never_listed(setup):
    """PX4 finds every compiled-in parameter by name; one no module looked up answers with index -1 (65535)."""
    proto, ctx, client = setup
    registry = ctx.vehicle.params
    count = len(registry)
    proto.handle(client.msg("PARAM_REQUEST_READ", 1, 1, b"MIS_DIST_1WP", -1), ctx)
    (msg,) = ctx.take("PARAM_VALUE")
    assert (msg.param_index, msg.param_count, msg.param_value) == (UNUSED_INDEX, count, 10000.0)
    proto.handle(_set(client, "MIS_DIST_1WP", 500.0, MAV_PARAM_TYPE_REAL32), ctx)
    (echo,) = ctx.take("PARAM_VALUE")
    assert (echo.param_index, echo.param_value) == (UNUSED_INDEX, 500.0)
    proto.tick(ctx)
    assert ctx.take() == []  # not re-sent on the links: PX4 re-sends only used parameters
    proto.handle(client.msg("PARAM_REQUEST_LIST", 1, 1), ctx)
    names = [m.param_id for m in _drain(proto, ctx)]
    assert "MIS_DIST_1WP" not in names and len(names) == count + 1


def test_mark_used_lists_a_parameter_in_name_order_and_counts_it(setup):
    proto, ctx, client = setup
    registry = ctx.vehicle.params
    count = len(registry)
    hash_before = registry.hash_check()
    registry.mark_used("MIS_DIST_1WP")
    registry.mark_used("MIS_TKO_LAND_REQ")
    assert len(registry) == count + 2 and registry.hash_check() != hash_before
    proto.handle(client.msg("PARAM_REQUEST_LIST", 1, 1), ctx)
    values = _drain(proto, ctx)
    names = [m.param_id for m in values[1:]]
    assert names == sorted(names) and {"MIS_DIST_1WP", "MIS_TKO_LAND_REQ"} <= set(names)
    assert all(m.param_count == count + 2 for m in values)
    assert [m.param_index for m in values[1:]] == list(range(count + 2))


def test_set_real_is_echoed_and_applied(setup):
    proto, ctx, client = setup
    proto.handle(_set(client, "BAT_LOW_THR", 0.2, MAV_PARAM_TYPE_REAL32), ctx)
    (echo,) = ctx.take("PARAM_VALUE")
    assert echo.param_id == "BAT_LOW_THR" and echo.param_type == MAV_PARAM_TYPE_REAL32
    assert echo.param_value == pytest.approx(0.2)
    assert ctx.vehicle.params.get("BAT_LOW_THR") == pytest.approx(0.2)


def test_set_echo_is_bit_equal_for_mavsdk(setup):
    proto, ctx, client = setup
    sent = struct.unpack("<f", struct.pack("<f", 0.3))[0]
    proto.handle(_set(client, "BAT_LOW_THR", sent, MAV_PARAM_TYPE_REAL32), ctx)
    (echo,) = ctx.take("PARAM_VALUE")
    assert struct.pack("<f", echo.param_value) == struct.pack("<f", sent)


def test_set_int32_bytewise(setup):
    proto, ctx, client = setup
    proto.handle(_set(client, "BAT1_N_CELLS", int32_to_float_bits(6), MAV_PARAM_TYPE_INT32), ctx)
    (echo,) = ctx.take("PARAM_VALUE")
    assert float_bits_to_int32(echo.param_value) == 6
    assert ctx.vehicle.params.get("BAT1_N_CELLS") == 6


def test_set_same_value_is_still_echoed(setup):
    proto, ctx, client = setup
    proto.handle(_set(client, "BAT1_N_CELLS", int32_to_float_bits(4), MAV_PARAM_TYPE_INT32), ctx)
    assert len(ctx.take("PARAM_VALUE")) == 1


def test_change_is_rebroadcast_on_every_link(setup):
    proto, ctx, client = setup
    other_ctx = MemoryContext(ctx.vehicle, link_name="gcs")
    other = ParamProtocol()
    other.tick(other_ctx)
    proto.handle(_set(client, "BAT_LOW_THR", 0.25, MAV_PARAM_TYPE_REAL32), ctx)
    ctx.take()
    proto.tick(ctx)
    other.tick(other_ctx)
    assert [m.param_id for m in ctx.take("PARAM_VALUE")] == ["BAT_LOW_THR"]
    assert [m.param_id for m in other_ctx.take("PARAM_VALUE")] == ["BAT_LOW_THR"]
    other.tick(other_ctx)
    assert other_ctx.take() == []  # sent once per change


def test_changes_from_the_shell_reach_the_links(setup):
    proto, ctx, _ = setup
    ctx.vehicle.params.set("BAT_CRIT_THR", 0.1)
    proto.tick(ctx)
    (msg,) = ctx.take("PARAM_VALUE")
    assert msg.param_id == "BAT_CRIT_THR" and msg.param_value == pytest.approx(0.1)


@pytest.mark.parametrize(
    ("name", "value", "type_code", "code"),
    [
        ("NO_SUCH_PARAM", 1.0, MAV_PARAM_TYPE_REAL32, PARAM_ERROR_DOES_NOT_EXIST),
        ("BAT_LOW_THR", int32_to_float_bits(1), MAV_PARAM_TYPE_INT32, PARAM_ERROR_TYPE_MISMATCH),
        ("BAT1_N_CELLS", 3.0, MAV_PARAM_TYPE_REAL32, PARAM_ERROR_TYPE_MISMATCH),
        ("BAT1_N_CELLS", 3.0, 2, PARAM_ERROR_TYPE_UNSUPPORTED),  # UINT8: PX4 has only INT32 and REAL32
    ],
)
def test_unknown_or_mistyped_set_gets_param_error_and_changes_nothing(setup, name, value, type_code, code):
    proto, ctx, client = setup
    before = ctx.vehicle.params.values()
    proto.handle(_set(client, name, value, type_code), ctx)
    err = _error(ctx)
    assert (err.param_id, err.param_index, err.error) == (name, -1, code)
    proto.tick(ctx)
    assert ctx.take() == []
    assert ctx.vehicle.params.values() == before


@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf, 5.0, -1.0])
def test_invalid_real_values_are_refused_with_a_text_and_param_error(setup, value):
    proto, ctx, client = setup
    proto.handle(_set(client, "BAT_LOW_THR", value, MAV_PARAM_TYPE_REAL32), ctx)
    err = _error(ctx)
    assert (err.param_id, err.error) == ("BAT_LOW_THR", PARAM_ERROR_VALUE_OUT_OF_RANGE)
    assert ctx.vehicle.params.get("BAT_LOW_THR") == pytest.approx(0.15)
    (event,) = ctx.vehicle.events
    assert event.severity == Severity.CRITICAL and event.module == "param" and "BAT_LOW_THR" in event.text


def test_out_of_range_int_is_refused(setup):
    proto, ctx, client = setup
    proto.handle(_set(client, "MAV_SYS_ID", int32_to_float_bits(300), MAV_PARAM_TYPE_INT32), ctx)
    assert _error(ctx).error == PARAM_ERROR_VALUE_OUT_OF_RANGE
    assert ctx.vehicle.params.get("MAV_SYS_ID") == 1


def test_a_parameter_without_a_range_takes_any_int32(setup):
    proto, ctx, client = setup
    for value in (-(2**31), 2**31 - 1):  # PX4's metadata states no range for ADSB_CALLSIGN_1
        proto.handle(_set(client, "ADSB_CALLSIGN_1", int32_to_float_bits(value), MAV_PARAM_TYPE_INT32), ctx)
        (echo,) = ctx.take("PARAM_VALUE")
        assert float_bits_to_int32(echo.param_value) == value == ctx.vehicle.params.get("ADSB_CALLSIGN_1")


def test_px4s_stated_range_is_kept_for_a_parameter_the_emulator_only_stores(setup):
    """ADSB_ICAO_ID: [-1, 16777215] in PX4's metadata (px4_param_meta.csv); the emulator never reads it."""
    proto, ctx, client = setup
    proto.handle(_set(client, "ADSB_ICAO_ID", int32_to_float_bits(2**24), MAV_PARAM_TYPE_INT32), ctx)
    assert _error(ctx).error == PARAM_ERROR_VALUE_OUT_OF_RANGE
    proto.handle(_set(client, "ADSB_ICAO_ID", int32_to_float_bits(2**24 - 1), MAV_PARAM_TYPE_INT32), ctx)
    (echo,) = ctx.take("PARAM_VALUE")
    assert float_bits_to_int32(echo.param_value) == 2**24 - 1 == ctx.vehicle.params.get("ADSB_ICAO_ID")


def test_hash_changes_with_values(setup):
    _, ctx, _ = setup
    before = ctx.vehicle.params.hash_check()
    ctx.vehicle.params.set("BAT_LOW_THR", 0.3)
    assert ctx.vehicle.params.hash_check() != before


def _crc32_part_bitwise(data: bytes, state: int) -> int:
    """PX4's crc32part (src/lib/crc/crc.c) written out bit by bit: reflected 0xEDB88320, no inversion."""
    for byte in data:
        state ^= byte
        for _ in range(8):
            state = (state >> 1) ^ (0xEDB88320 if state & 1 else 0)
    return state


def test_hash_is_px4s_crc_over_names_and_value_bytes():
    from sitl_emu.params import ParamRegistry, integer, real

    registry = ParamRegistry([real("B_REAL", 2.5), integer("A_INT", 7)])
    expected = 0
    for name, raw in (("A_INT", struct.pack("<i", 7)), ("B_REAL", struct.pack("<f", 2.5))):
        expected = _crc32_part_bitwise(name.encode(), expected)
        expected = _crc32_part_bitwise(raw, expected)
    assert registry.hash_check() == expected
