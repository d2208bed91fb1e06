"""The whole parameter list over loopback UDP, as a ground station downloads it from the real Vehicle.

The reference is what real PX4 SITL (SIH quadrotor, fresh boot) sent after PARAM_REQUEST_LIST
(../shared/reference/px4-params.json; the packaged catalog when the reference is not beside the repository).
Everything runs in lockstep simulated time.
"""

from __future__ import annotations

import struct

import pytest
from support.fakes import Harness

from sitl_emu.mavlink.protocols.params import (
    HASH_CHECK_INDEX,
    MAV_PARAM_TYPE_INT32,
    MAV_PARAM_TYPE_REAL32,
    MAV_PARAM_TYPE_UINT32,
    PARAM_ERROR_DOES_NOT_EXIST,
    PARAM_ERROR_TYPE_MISMATCH,
    PARAM_ERROR_VALUE_OUT_OF_RANGE,
    float_bits_to_int32,
    int32_to_float_bits,
)
from sitl_emu.params.catalog import EMULATOR_DEFAULTS
from sitl_emu.params.registry import ParamType, float32, same_value
from sitl_emu.vehicle.vehicle import Vehicle

from ...params.test_registry import px4_list

TYPE_NAMES = {MAV_PARAM_TYPE_INT32: "INT32", MAV_PARAM_TYPE_REAL32: "REAL32"}


@pytest.fixture
def h():
    harness = Harness(Vehicle(), handler_classes=None)  # None: every protocol handler, as serve
    harness.gcs.heartbeat()
    harness.io()
    yield harness
    harness.close()


def _values(h: Harness, start: int = 0) -> list:
    return h.gcs.of_type("PARAM_VALUE")[start:]


def _download(h: Harness) -> list:
    start = len(_values(h))
    h.gcs.send(h.gcs.mav.param_request_list_encode(1, 1))
    h.run(1.0)
    return _values(h, start)


def _decoded(msg) -> float:
    return float_bits_to_int32(msg.param_value) if msg.param_type == MAV_PARAM_TYPE_INT32 else msg.param_value


def _hash(msg) -> int:
    return int(struct.unpack("<I", struct.pack("<f", msg.param_value))[0])


def test_the_whole_list_over_udp_is_px4s(h):
    px4 = px4_list()
    got = _download(h)
    first, rest = got[0], got[1:]
    assert (first.param_id, first.param_index, first.param_type) == ("_HASH_CHECK", HASH_CHECK_INDEX,
                                                                     MAV_PARAM_TYPE_UINT32)
    assert first.param_count == len(px4)  # _HASH_CHECK itself is not counted
    assert len(rest) == len(px4) == 994
    assert [m.param_id for m in rest] == sorted(px4, key=lambda n: px4[n]["index"])
    assert [m.param_index for m in rest] == [px4[m.param_id]["index"] for m in rest] == list(range(len(px4)))
    assert all(m.param_count == len(px4) for m in rest)
    for m in rest:
        ref = px4[m.param_id]
        assert TYPE_NAMES[m.param_type] == ref["type"], m.param_id
        if m.param_id not in EMULATOR_DEFAULTS:
            assert same_value(ParamType(ref["type"]), _decoded(m), ref["value"]), m.param_id
    assert _decoded(next(m for m in rest if m.param_id == "SIH_LOC_H0")) == float32(489.4)  # SIH's, as recorded


def test_the_hash_changes_on_a_set_and_matches_the_registry(h):
    before = _download(h)[0]
    assert _hash(before) == h.vehicle.params.hash_check()
    h.gcs.send(h.gcs.mav.param_set_encode(1, 1, b"MPC_XY_VEL_MAX", 8.0, MAV_PARAM_TYPE_REAL32))
    h.run(0.05)
    after = _download(h)[0]
    assert _hash(after) != _hash(before) and _hash(after) == h.vehicle.params.hash_check()


def test_read_by_index_and_by_name(h):
    registry = h.vehicle.params
    index = registry.index_of("MIS_TAKEOFF_ALT")
    h.gcs.send(h.gcs.mav.param_request_read_encode(1, 1, b"", index))
    h.gcs.send(h.gcs.mav.param_request_read_encode(1, 1, b"BAT1_N_CELLS", -1))
    h.run(0.02)
    by_index, by_name = _values(h)
    assert (by_index.param_id, by_index.param_index, by_index.param_value) == ("MIS_TAKEOFF_ALT", index, 2.5)
    assert by_name.param_index == registry.index_of("BAT1_N_CELLS") and _decoded(by_name) == 4


def test_param_errors_go_to_the_requester(h):
    mav = h.gcs.mav
    h.gcs.send(mav.param_request_read_encode(1, 1, b"NO_SUCH_PARAM", -1))
    h.gcs.send(mav.param_request_read_encode(1, 1, b"", 5000))
    h.gcs.send(mav.param_set_encode(1, 1, b"NO_SUCH_PARAM", 1.0, MAV_PARAM_TYPE_REAL32))
    h.gcs.send(mav.param_set_encode(1, 1, b"BAT1_N_CELLS", 3.0, MAV_PARAM_TYPE_REAL32))
    h.gcs.send(mav.param_set_encode(1, 1, b"BAT1_N_CELLS", int32_to_float_bits(99), MAV_PARAM_TYPE_INT32))
    h.run(0.02)
    errors = h.gcs.of_type("PARAM_ERROR")
    assert [(e.param_id, e.param_index, e.error) for e in errors] == [
        ("NO_SUCH_PARAM", -1, PARAM_ERROR_DOES_NOT_EXIST), ("", 5000, PARAM_ERROR_DOES_NOT_EXIST),
        ("NO_SUCH_PARAM", -1, PARAM_ERROR_DOES_NOT_EXIST), ("BAT1_N_CELLS", -1, PARAM_ERROR_TYPE_MISMATCH),
        ("BAT1_N_CELLS", -1, PARAM_ERROR_VALUE_OUT_OF_RANGE)]
    assert all((e.target_system, e.target_component) == (255, 190) for e in errors)
    assert h.vehicle.params.get("BAT1_N_CELLS") == 4 and _values(h) == []
    assert "BAT1_N_CELLS" in "".join(m.text for m in h.gcs.of_type("STATUSTEXT"))
