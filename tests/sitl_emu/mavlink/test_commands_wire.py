"""Commands over the wire with the real Vehicle: ACK codes and texts, message intervals, requests, the seed flight.

ACK codes and texts: reference sections 3.2-3.14 (PX4 v1.15-v1.17). Everything runs in lockstep simulated time.
"""

from __future__ import annotations

import math
from collections import Counter

import pytest
from pymavlink.dialects.v20 import development as dialect
from support.fakes import Harness

from sitl_emu.mavlink.version import ProtocolVersionMessage
from sitl_emu.px4 import MavCmd
from sitl_emu.vehicle.vehicle import Vehicle

NAN = math.nan
dialect.mavlink_map.setdefault(300, ProtocolVersionMessage)  # let the test client parse PROTOCOL_VERSION


@pytest.fixture
def h():
    harness = Harness(Vehicle())
    harness.gcs.heartbeat()
    harness.io()
    yield harness
    harness.close()


def _acks(client, start=0):
    return [(a.command, a.result) for a in client.of_type("COMMAND_ACK")[start:]]


def _texts(client, start=0):
    return "".join(m.text for m in client.of_type("STATUSTEXT")[start:])


def _ask(h, command, *params, wait_s=0.1):
    n_ack, n_txt = len(h.gcs.of_type("COMMAND_ACK")), len(h.gcs.of_type("STATUSTEXT"))
    h.gcs.heartbeat()
    h.gcs.command_long(command, *params)
    h.run(wait_s)
    return [r for c, r in _acks(h.gcs, n_ack) if c == command], _texts(h.gcs, n_txt)


# (command, params, expected results, text that must appear) for a ready, disarmed vehicle in Hold
READY_CASES = [
    (MavCmd.COMPONENT_ARM_DISARM, (1,), [0], "Armed by external command\t"),
    (MavCmd.COMPONENT_ARM_DISARM, (2,), [], "Unsupported ARM_DISARM param: 2.000"),
    (MavCmd.COMPONENT_ARM_DISARM, (0,), [0], ""),
    (MavCmd.DO_SET_MODE, (1, 4, 3), [0], ""),
    (MavCmd.DO_SET_MODE, (1, 6, 0), [0], ""),  # OFFBOARD while disarmed: always accepted
    (MavCmd.DO_SET_MODE, (1, 99, 0), [1], "Unsupported main mode"),
    (MavCmd.DO_SET_MODE, (1, 4, 7), [1], "Unsupported auto mode"),
    (MavCmd.NAV_TAKEOFF, (), [0], ""),  # accepted while disarmed; the takeoff (and its text) starts at arming
    (MavCmd.NAV_LAND, (), [0], "Landing at current position\t"),
    (MavCmd.NAV_RETURN_TO_LAUNCH, (), [0], "Returning to launch\t"),
    (MavCmd.DO_REPOSITION, (-1, 1, 0, NAN, NAN, NAN, NAN), [0], ""),
    (MavCmd.MISSION_START, (0, 0), [2], "Mission start denied! No valid mission\t"),
    (MavCmd.PREFLIGHT_CALIBRATION, (0, 0, 0, 0, 0, 0, 0), [2], "Calibration denied: not supported in SIH mode\t"),
    (31000, (), [3], ""),
    (MavCmd.SET_MESSAGE_INTERVAL, (0, 1e6), [4], ""),  # HEARTBEAT's rate cannot be changed
    (MavCmd.REQUEST_MESSAGE, (148,), [0], ""),
    (MavCmd.REQUEST_AUTOPILOT_CAPABILITIES, (1,), [0], ""),
    (MavCmd.REQUEST_PROTOCOL_VERSION, (1,), [0], ""),
    (MavCmd.GET_HOME_POSITION, (), [0], ""),
]


@pytest.mark.parametrize("command, params, results, text", READY_CASES)
def test_ack_codes_and_texts_when_ready(h, command, params, results, text):
    h.run(2.5)
    got, texts = _ask(h, command, *params)
    assert got == results
    assert text in texts


def test_before_ready_arming_is_rejected_and_home_is_denied(h):
    got, texts = _ask(h, MavCmd.COMPONENT_ARM_DISARM, 1)
    assert got == [1] and "Arming denied: Resolve system health failures first\t" in texts
    assert _ask(h, MavCmd.REQUEST_MESSAGE, 242)[0] == [2]
    assert _ask(h, MavCmd.GET_HOME_POSITION)[0] == [2]


def test_armed_offboard_without_setpoints_is_temporarily_rejected(h):
    h.run(2.5)
    assert _ask(h, MavCmd.COMPONENT_ARM_DISARM, 1)[0] == [0]
    assert _ask(h, MavCmd.DO_SET_MODE, 1 | 128, 6, 0)[0] == [1]
    assert _ask(h, MavCmd.COMPONENT_ARM_DISARM, 0)[0] == [0]


def test_arm_then_takeoff_climbs_in_auto_takeoff_then_holds(h):
    h.run(2.5)
    assert _ask(h, MavCmd.COMPONENT_ARM_DISARM, 1)[0] == [0]
    got, texts = _ask(h, MavCmd.NAV_TAKEOFF, wait_s=1.5)
    assert got == [0] and "Using default takeoff altitude: 2.5 m\t" in texts
    assert h.gcs.of_type("HEARTBEAT")[-1].custom_mode == 33816576  # AUTO.TAKEOFF
    assert h.run_until(lambda: h.api.of_type("EXTENDED_SYS_STATE")[-1].landed_state == 3, 4.0)  # TAKEOFF
    h.run(8.0)
    assert h.gcs.of_type("HEARTBEAT")[-1].custom_mode == 50593792  # then Hold
    assert h.gcs.of_type("LOCAL_POSITION_NED")[-1].z == pytest.approx(-2.5, abs=0.3)


def test_set_mode_message_is_acked_as_do_set_mode(h):
    h.run(2.5)
    h.gcs.send(h.gcs.mav.set_mode_encode(1, 1, (5 << 24) | (4 << 16)))
    h.run(1.1)
    assert _acks(h.gcs) == [(MavCmd.DO_SET_MODE, 0)]
    assert h.gcs.of_type("HEARTBEAT")[-1].custom_mode == 84148224


def test_set_and_get_message_interval_apply_to_their_own_link(h):
    h.run(2.0)
    h.api.command_long(MavCmd.SET_MESSAGE_INTERVAL, 30, 100_000)  # ATTITUDE at 10 Hz on the API link only
    # ODOMETRY at 20 Hz on GCS (NaN params are fine)
    h.gcs.command_long(MavCmd.SET_MESSAGE_INTERVAL, 331, 50_000, NAN, NAN, NAN, NAN, NAN)
    h.gcs.command_long(MavCmd.SET_MESSAGE_INTERVAL, 32, -1)  # stop LOCAL_POSITION_NED on GCS
    h.io()
    n_api, n_gcs = len(h.api.received), len(h.gcs.received)
    h.run(2.0)
    api = Counter(m.get_type() for m in h.api.received[n_api:])
    gcs = Counter(m.get_type() for m in h.gcs.received[n_gcs:])
    assert api["ATTITUDE"] == pytest.approx(20, abs=1) and gcs["ATTITUDE"] == pytest.approx(100, abs=1)
    assert gcs["ODOMETRY"] == pytest.approx(40, abs=1) and gcs["LOCAL_POSITION_NED"] == 0
    assert api["LOCAL_POSITION_NED"] == pytest.approx(60, abs=1)
    for msg_id in (30, 32, 0):
        h.gcs.command_long(MavCmd.GET_MESSAGE_INTERVAL, msg_id)
    h.gcs.command_long(MavCmd.REQUEST_MESSAGE, 244, 331)
    h.api.command_long(MavCmd.GET_MESSAGE_INTERVAL, 30)
    h.io()
    gcs_iv = [(m.message_id, m.interval_us) for m in h.gcs.of_type("MESSAGE_INTERVAL")]
    assert gcs_iv == [(30, 20_000), (32, 0), (0, 1_000_000), (331, 50_000)]  # stopped: 0, as PX4's code does
    assert [(m.message_id, m.interval_us) for m in h.api.of_type("MESSAGE_INTERVAL")] == [(30, 100_000)]
    h.gcs.command_long(MavCmd.SET_MESSAGE_INTERVAL, 32, 0)  # back to the default rate
    h.io()
    h.gcs.command_long(MavCmd.GET_MESSAGE_INTERVAL, 32)
    h.io()
    assert h.gcs.of_type("MESSAGE_INTERVAL")[-1].interval_us == 20_000


@pytest.mark.parametrize("interval_us", [math.inf, -math.inf, 2e12])
def test_an_endless_interval_stops_the_stream_as_px4_does(h, interval_us):
    """set_message_interval: rate = 1e6 / interval; configure_stream deletes a stream whose rate is not above 1e-6."""
    h.run(0.5)
    assert _ask(h, MavCmd.SET_MESSAGE_INTERVAL, 30, interval_us)[0] == [0]
    h.gcs.command_long(MavCmd.GET_MESSAGE_INTERVAL, 30)
    h.io()
    assert h.gcs.of_type("MESSAGE_INTERVAL")[-1].interval_us == 0
    n = len(h.gcs.received)
    h.run(1.0)
    assert not [m for m in h.gcs.received[n:] if m.get_type() == "ATTITUDE"]


@pytest.mark.parametrize("params", [(9999, 1000), (30, 1000, 1), (30, 1000, 0, 2), (30, 1000, 0, 0, 0, 0, 1)])
def test_set_message_interval_failures(h, params):
    assert _ask(h, MavCmd.SET_MESSAGE_INTERVAL, *params)[0] == [4]


def test_request_message_sends_the_message_before_the_ack(h):
    h.run(2.5)
    for msg_id in (148, 300, 242, 1, 245):
        h.gcs.command_long(MavCmd.REQUEST_MESSAGE, msg_id)
    h.gcs.command_long(MavCmd.REQUEST_AUTOPILOT_CAPABILITIES, 1, target=(1, 0))  # legacy, any component
    h.gcs.command_long(MavCmd.REQUEST_MESSAGE, 12345)  # no such stream
    n = len(h.gcs.received)
    h.io()
    got = [m.get_type() for m in h.gcs.received[n:] if m.get_type() not in ("HEARTBEAT",)]
    expected = ["AUTOPILOT_VERSION", "COMMAND_ACK", "PROTOCOL_VERSION", "COMMAND_ACK", "HOME_POSITION", "COMMAND_ACK",
                "SYS_STATUS", "COMMAND_ACK", "EXTENDED_SYS_STATE", "COMMAND_ACK", "AUTOPILOT_VERSION", "COMMAND_ACK",
                "COMMAND_ACK"]
    assert [t for t in got if t in set(expected)][:len(expected)] == expected
    assert _acks(h.gcs)[-1] == (512, 2)
    av = h.gcs.of_type("AUTOPILOT_VERSION")[0]
    assert av.capabilities == 59647 and av.flight_sw_version == 0x010F04FF
    pv = h.gcs.of_type("PROTOCOL_VERSION")[0]
    assert (pv.version, pv.min_version, pv.max_version) == (200, 100, 203)


@pytest.mark.slow
def test_seed_sequence_arm_stream_offboard_climb_follow_then_loss_returns(h):
    """The seed workflow: arm, stream setpoints, OFFBOARD, climb, follow, stop streaming -> failsafe AUTO.RTL."""
    target = {"x": 0.0, "z": -5.0, "on": True}
    tick = {"n": 0}

    def stream():
        tick["n"] += 1
        if tick["n"] % 5 == 0:
            h.gcs.heartbeat()
        if target["on"] and tick["n"] % 12 == 0:  # ~20 Hz
            h.api.send(h.api.mav.set_position_target_local_ned_encode(
                0, 1, 1, 1, 3576, target["x"], 0.0, target["z"], 0, 0, 0, 0, 0, 0, 0, 0))
    h.run(2.5, stream)
    h.api.command_long(MavCmd.COMPONENT_ARM_DISARM, 1.0)
    h.run(0.6, stream)  # ten setpoints and more
    h.api.command_long(MavCmd.DO_SET_MODE, 1 | 128, 6, 0)
    h.run(0.1, stream)
    assert _acks(h.api) == [(MavCmd.COMPONENT_ARM_DISARM, 0), (MavCmd.DO_SET_MODE, 0)]
    h.run(10.0, stream)
    pos = h.api.of_type("LOCAL_POSITION_NED")[-1]
    assert pos.z == pytest.approx(-5.0, abs=0.3) and abs(pos.x) < 0.3
    assert h.api.of_type("HEARTBEAT")[-1].custom_mode == 393216
    target["x"] = 4.0
    h.run(8.0, stream)
    pos = h.api.of_type("LOCAL_POSITION_NED")[-1]
    assert pos.x == pytest.approx(4.0, abs=0.3) and pos.z == pytest.approx(-5.0, abs=0.3)
    target["on"] = False
    n_txt = len(h.gcs.of_type("STATUSTEXT"))
    h.run(2.0, stream)
    hb = h.api.of_type("HEARTBEAT")[-1]
    assert hb.custom_mode == 84148224 and hb.base_mode & 128
    assert "Failsafe activated\t" in _texts(h.gcs, n_txt)


def test_available_modes_on_request_all_or_one(h):
    h.gcs.command_long(MavCmd.REQUEST_MESSAGE, 435, 0)
    h.io()
    modes = h.gcs.of_type("AVAILABLE_MODES")
    assert [m.mode_index for m in modes] == list(range(1, len(modes) + 1))
    assert {m.number_modes for m in modes} == {len(modes)}
    by_mode = {m.custom_mode: m for m in modes}
    assert by_mode[50593792].mode_name == "Hold" and by_mode[50593792].standard_mode == 0
    assert by_mode[84148224].standard_mode == 5 and by_mode[84148224].mode_name == ""  # Return = SAFE_RECOVERY
    assert by_mode[196608].properties == 0 and by_mode[393216].properties == 1  # Position basic, Offboard advanced
    assert _acks(h.gcs) == [(MavCmd.REQUEST_MESSAGE, 0)]
    h.gcs.command_long(MavCmd.REQUEST_MESSAGE, 435, 3)
    h.gcs.command_long(MavCmd.REQUEST_MESSAGE, 435, len(modes) + 1)
    h.io()
    assert h.gcs.of_type("AVAILABLE_MODES")[-1].mode_index == 3
    assert _acks(h.gcs)[1:] == [(MavCmd.REQUEST_MESSAGE, 0), (MavCmd.REQUEST_MESSAGE, 2)]
