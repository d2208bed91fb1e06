"""The ground station's view of the vehicle at rest, as PX4 SIH gives it: stream set and rates, SYS_STATUS bits,
HEARTBEAT base_mode per mode, and REQUEST_MESSAGE / SET_MESSAGE_INTERVAL for the streamed messages.

Over loopback UDP in simulated time; the client on the GCS link acts as QGroundControl (sysid 255, compid 190,
heartbeat at 1 Hz, nothing requested). Messages are counted by the id in each frame's header, so the ones pymavlink
does not know (extra_messages.py) count like the others.
"""

from __future__ import annotations

import json
import math
from collections import Counter
from pathlib import Path
from typing import Any

import pytest
from pymavlink.dialects.v20 import development as dialect
from support.fakes import HOME, Harness
from support.ports import pending_datagrams

from sitl_emu.mavlink.protocols.events import EventsProtocol
from sitl_emu.mavlink.wire import extra_messages
from sitl_emu.px4 import MavCmd
from sitl_emu.vehicle.vehicle import Vehicle

# ../shared/reference/px4-gcs-streams.json, copied so the test runs anywhere: message id -> rate (Hz) PX4 SIH streams
# on its GCS link at rest, counted over 10 s by a client acting as QGC.
PX4_GCS_RATES_HZ = {
    0: 0.989, 1: 0.989, 4: 0.1, 8: 0.989, 24: 4.948, 29: 0.989, 30: 49.481, 31: 49.481, 32: 49.481, 33: 49.482,
    36: 49.481, 42: 0.987, 74: 3.958, 83: 49.481, 85: 49.481, 132: 0.495, 141: 0.989, 147: 0.495, 230: 0.495,
    241: 0.1, 242: 0.495, 245: 0.989, 290: 0.989, 291: 0.989, 380: 0.491, 411: 0.329, 436: 0.495, 441: 0.989,
    514: 0.495, 12901: 0.989, 12904: 0.989,
}
REFERENCE_FILE = Path("/work/shared/reference/px4-gcs-streams.json")
# What the emulator does not send, and why (nothing since it speaks the events protocol: CURRENT_EVENT_SEQUENCE)
NOT_SENT: dict[int, str] = {}
# Sent but not a stream, in PX4 as here: the events protocol's CURRENT_EVENT_SEQUENCE, which REQUEST_MESSAGE and
# SET_MESSAGE_INTERVAL do not reach
NOT_STREAMS = {411}
PRESENCE_ONLY_HZ = 0.2  # PING and VIBRATION (0.1 Hz) come once or twice in 10 s: judged by presence

PRESENT, ENABLED, HEALTH = 0x0300C02F, 0x0301C02F, 0x1320C83F  # PX4 SIH at rest (issue 13)


class Tap:
    """A harness stepped in lockstep whose clients' datagrams are kept raw, per link."""

    def __init__(self) -> None:
        # the events protocol, which every PX4 mavlink instance runs, sends CURRENT_EVENT_SEQUENCE
        self.h = Harness(Vehicle(home=HOME), handler_classes=[EventsProtocol], epoch_unix_us=1_700_000_000_000_000)
        self.raw: dict[str, list[bytes]] = {"api": [], "gcs": []}
        self._next_heartbeat_us = 0

    def run(self, seconds: float, every_step: Any = None) -> None:
        h = self.h
        for _ in range(round(seconds * 1e6 / h.vehicle.dt_us)):
            if h.vehicle.time_us >= self._next_heartbeat_us:  # QGC's heartbeat, 1 Hz
                h.gcs.heartbeat()
                self._next_heartbeat_us = h.vehicle.time_us + 1_000_000
            h.vehicle.step()
            if every_step is not None:
                every_step()
            h.node.step_io(h.vehicle.time_us)
            for name, client in (("api", h.api), ("gcs", h.gcs)):
                self.raw[name] += pending_datagrams(client.sock)

    def clear(self) -> None:
        self.raw = {"api": [], "gcs": []}

    def ids(self, link: str) -> Counter[int]:
        return Counter(_msg_id(d) for d in self.raw[link] if d[5:7] == b"\x01\x01")

    def messages(self, link: str, msg_id: int) -> list[Any]:
        """The vehicle's messages of one id on a link, decoded (pymavlink, or extra_messages.decode as a dict)."""
        frames = [d for d in self.raw[link] if d[5:7] == b"\x01\x01" and _msg_id(d) == msg_id]
        if msg_id in extra_messages.MESSAGE_IDS:
            return [extra_messages.decode(msg_id, d[10:-2]) for d in frames]
        parser = dialect.MAVLink(None)
        return [m for d in frames for m in parser.parse_buffer(d) or []]

    def last(self, link: str, msg_id: int) -> Any:
        return self.messages(link, msg_id)[-1]

    def command(self, command: int, *params: float, link: str = "gcs") -> None:
        client = self.h.gcs if link == "gcs" else self.h.api
        client.command_long(command, *params)

    def acks(self, link: str = "gcs") -> list[tuple[int, int]]:
        return [(a.command, a.result) for a in self.messages(link, 77)]

    def close(self) -> None:
        self.h.close()


def _msg_id(frame: bytes) -> int:
    return int.from_bytes(frame[7:10], "little")


@pytest.fixture
def tap():
    t = Tap()
    yield t
    t.close()


def _stream_position_setpoints(tap: Tap) -> Any:
    """A 20 Hz SET_POSITION_TARGET_LOCAL_NED stream (position, MAVSDK's mask) on the API link."""
    api = tap.h.api
    state = {"n": 0}

    def step() -> None:
        state["n"] += 1
        if state["n"] % 12 == 0:
            api.send(api.mav.set_position_target_local_ned_encode(0, 1, 1, 1, 2552, 0, 0, -3, 0, 0, 0, 0, 0, 0, 0, 0))
    return step


# --- the stream set and rates ---------------------------------------------------------------------------------------
def test_the_reference_copy_matches_the_reference_file():
    if not REFERENCE_FILE.exists():
        pytest.skip("no ../shared/reference here")
    messages = json.loads(REFERENCE_FILE.read_text())["messages"]
    assert {int(k): v["rate_hz"] for k, v in messages.items()} == PX4_GCS_RATES_HZ


def test_gcs_link_streams_px4_sih_message_set_at_its_rates_at_rest(tap):
    tap.run(3.0)  # boot: the estimator is ready, home is set
    tap.clear()
    tap.run(10.0)
    counts = tap.ids("gcs")
    expected = set(PX4_GCS_RATES_HZ) - set(NOT_SENT)
    assert set(counts) == expected, (sorted(set(counts) - expected), sorted(expected - set(counts)))
    for msg_id in expected:
        px4_hz, hz = PX4_GCS_RATES_HZ[msg_id], counts[msg_id] / 10.0
        if px4_hz < PRESENCE_ONLY_HZ:
            continue
        assert abs(hz - px4_hz) <= 0.25 * px4_hz, (msg_id, hz, px4_hz)


def test_onboard_link_streams_the_position_and_attitude_targets_at_rest_at_10_hz(tap):
    tap.run(3.0)
    tap.clear()
    tap.run(10.0)
    counts = tap.ids("api")
    assert counts[85] == pytest.approx(100, abs=1) and counts[83] == pytest.approx(100, abs=1)
    target = tap.last("api", 85)
    # mc_pos_control's idle setpoint while not flying: no position or velocity, acceleration (0, 0, 100), yaw held
    assert target.coordinate_frame == 1 and target.type_mask == 0b111111
    assert (target.afx, target.afy, target.afz) == (0.0, 0.0, 100.0)
    assert (target.yaw, target.yaw_rate) == pytest.approx((0.0, 0.0), abs=1e-6)
    att = tap.last("api", 83)
    assert att.thrust == 0.0 and att.q == pytest.approx([1.0, 0.0, 0.0, 0.0], abs=1e-6)
    assert counts[36] == pytest.approx(100, abs=1)  # SERVO_OUTPUT_RAW 10 Hz, PX4's onboard default


# --- contents that follow the vehicle -------------------------------------------------------------------------------
def _takeoff(tap: Tap) -> None:
    tap.run(3.0)
    tap.command(MavCmd.COMPONENT_ARM_DISARM, 1.0)
    tap.command(MavCmd.NAV_TAKEOFF)
    tap.run(14.0)  # PX4's spool-up and ramp, the climb, then Hold settling at 2.5 m


def test_at_rest_outputs_are_disarmed_and_the_escs_idle(tap):
    tap.run(3.0)
    servo = tap.last("gcs", 36)
    assert [getattr(servo, f"servo{i}_raw") for i in range(1, 17)] == [900] * 16
    esc = tap.last("gcs", 291)
    assert esc["rpm"] == [0, 0, 0, 0] and esc["current"] == [0.0] * 4
    assert esc["voltage"] == pytest.approx([11.1] * 4)
    info = tap.last("gcs", 290)
    assert (info["count"], info["info"], info["temperature"]) == (4, 0b1111, [2000] * 4)


@pytest.mark.slow
def test_in_flight_outputs_follow_the_mixer_and_the_escs_the_motors(tap):
    _takeoff(tap)
    assert tap.h.vehicle.snapshot().landed_state == 2  # hovering
    servo = tap.last("gcs", 36)
    motors = [getattr(servo, f"servo{i}_raw") for i in range(1, 5)]
    assert all(1400 < pwm < 1700 for pwm in motors), motors  # hover thrust about 0.5
    assert [getattr(servo, f"servo{i}_raw") for i in range(5, 17)] == [900] * 12
    esc = tap.last("gcs", 291)
    assert all(2400 < rpm < 3600 for rpm in esc["rpm"]) and all(7.0 < a < 9.5 for a in esc["current"])
    target = tap.last("gcs", 85)
    assert target.z == pytest.approx(-2.5, abs=0.1) and not target.type_mask & 0b111  # Hold's position setpoint
    assert tap.last("gcs", 83).thrust == pytest.approx(0.5, abs=0.1)
    assert tap.last("gcs", 132).current_distance == pytest.approx(250, abs=10)  # cm, the range finder below
    vib = tap.last("gcs", 241)
    assert vib.vibration_z > 5 * 0.00098  # SIH's IMU is noisier with the motors spinning


def test_estimator_reports_and_mission_progress(tap):
    tap.run(1.0)
    assert tap.last("gcs", 230).flags & 0b10 == 0, "no horizontal velocity before GPS is fused"
    tap.run(2.0)
    est = tap.last("gcs", 230)
    assert est.flags == 895 and 0 < est.pos_horiz_ratio < 0.5 and 0 < est.pos_horiz_accuracy < 1
    vib = tap.last("gcs", 241)
    assert 0 < vib.vibration_z < 0.01 and 0 < vib.vibration_y < 0.001 and vib.clipping_0 == 0
    fusion = tap.last("gcs", 514)
    assert fusion["active"][0] == 1 and fusion["active"][4] == 1 and all(math.isnan(r) for r in fusion["test_ratio"])
    mission = tap.last("gcs", 42)
    assert (mission.seq, mission.total) == (0, 65535)
    assert tap.last("gcs", 380)["safe_return"] == 100  # on the ground: PX4's RTL_TIME_MARGIN alone
    link = tap.last("gcs", 8)
    assert link["messages_sent"] > 500 and link["messages_received"] >= 2 and link["tx_rate"] > 10_000


# --- SYS_STATUS ----------------------------------------------------------------------------------------------------
def _bits(msg: Any) -> tuple[int, int, int]:
    return msg.onboard_control_sensors_present, msg.onboard_control_sensors_enabled, msg.onboard_control_sensors_health


def test_sys_status_bits_at_rest_are_px4_sihs(tap):
    tap.run(0.5)
    present, enabled, health = _bits(tap.last("gcs", 1))
    assert present == PRESENT
    assert health & 0x10204820 == 0, "GPS, attitude, AHRS, local position and PREARM unhealthy before the estimator"
    assert enabled == PRESENT | 0x10000 | 0x204800, "unhealthy components read enabled (required but missing)"
    tap.run(2.5)
    assert _bits(tap.last("gcs", 1)) == (PRESENT, ENABLED, HEALTH)


def test_sys_status_bits_when_armed_and_in_failsafe(tap):
    step = _stream_position_setpoints(tap)
    tap.run(3.0, step)
    tap.command(MavCmd.COMPONENT_ARM_DISARM, 1.0, link="api")
    tap.command(MavCmd.DO_SET_MODE, 1, 6, 0, link="api")
    tap.run(6.0, step)
    hb = tap.last("gcs", 0)
    assert (hb.base_mode, hb.custom_mode, hb.system_status) == (145, 393216, 4)  # OFFBOARD, armed, active
    assert _bits(tap.last("gcs", 1)) == (PRESENT, ENABLED, HEALTH)  # armed: nothing changes
    tap.run(3.0)  # the setpoints stop: failsafe, Return
    hb = tap.last("gcs", 0)
    assert (hb.custom_mode, hb.system_status) == (84148224, 5)  # AUTO.RTL, CRITICAL
    assert _bits(tap.last("gcs", 1)) == (PRESENT, ENABLED, HEALTH), "Return can run: still armable in force"


def test_prearm_check_follows_the_mode_in_force(tap):
    tap.run(3.0)
    tap.command(MavCmd.DO_SET_MODE, 1, 4, 6)  # AUTO.LAND while disarmed: accepted, but it prevents arming
    tap.run(1.5)
    present, enabled, health = _bits(tap.last("gcs", 1))
    assert (present, enabled, health) == (PRESENT, ENABLED, HEALTH & ~0x10000000)
    assert tap.last("gcs", 0).system_status == 0  # UNINIT: arming checks fail for Land


# --- HEARTBEAT base_mode ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize(("main", "sub", "base_mode"), [
    (1, 0, 81), (7, 0, 81), (2, 0, 81), (3, 0, 81),  # Manual, Stabilized, Altitude, Position: manual + stabilized
    (5, 0, 65),  # Acro: manual input only
    (4, 3, 29), (4, 2, 29), (4, 4, 29), (4, 5, 29), (4, 6, 29), (4, 9, 29),  # AUTO.*: auto, guided, stabilized
    (4, 8, 17),  # Follow Target: stabilized only (neither auto nor manual in control_mode.cpp)
    (6, 0, 1),  # Offboard before any setpoint
])
def test_base_mode_in_every_mode_disarmed(tap, main, sub, base_mode):
    tap.run(2.5)
    tap.command(MavCmd.DO_SET_MODE, 1, main, sub)
    tap.run(1.2)
    assert tap.acks() == [(MavCmd.DO_SET_MODE, 0)]
    hb = tap.last("gcs", 0)
    assert hb.custom_mode == (sub << 24) | (main << 16) and hb.base_mode == base_mode


def test_offboard_base_mode_is_17_once_setpoints_came_and_stays_so_when_they_stop(tap):
    step = _stream_position_setpoints(tap)
    tap.run(2.5, step)
    tap.command(MavCmd.DO_SET_MODE, 1, 6, 0)
    tap.run(1.2, step)
    assert tap.last("gcs", 0).base_mode == 17
    tap.run(3.0)  # disarmed: no failsafe; commander keeps the last offboard_control_mode
    hb = tap.last("gcs", 0)
    assert (hb.custom_mode, hb.base_mode) == (393216, 17)
    tap.command(MavCmd.DO_SET_MODE, 1, 4, 3)
    tap.run(1.2)
    tap.command(MavCmd.COMPONENT_ARM_DISARM, 1.0)
    tap.run(1.2)
    assert tap.last("gcs", 0).base_mode == 29 | 128  # Hold armed


# --- REQUEST_MESSAGE / SET_MESSAGE_INTERVAL ------------------------------------------------------------------------
REQUESTABLE = sorted(set(PX4_GCS_RATES_HZ) - set(NOT_SENT) - NOT_STREAMS - {0})


def test_request_message_answers_every_streamed_message_before_its_ack(tap):
    tap.run(3.0)
    for msg_id in REQUESTABLE:
        tap.command(MavCmd.SET_MESSAGE_INTERVAL, msg_id, -1)  # stop the stream: only the answer may bring it
    tap.run(0.1)
    tap.clear()
    for msg_id in REQUESTABLE:
        tap.command(MavCmd.REQUEST_MESSAGE, msg_id)
        tap.run(0.004)
        frames = [d for d in tap.raw["gcs"] if d[5:7] == b"\x01\x01"]
        ids = [_msg_id(d) for d in frames]
        assert msg_id in ids, msg_id
        ack_at = next(i for i, d in enumerate(frames) if _msg_id(d) == 77)
        assert ids.index(msg_id) < ack_at, f"{msg_id} goes out before the ACK"
        tap.clear()


def test_request_message_acks_accepted_for_the_new_messages(tap):
    tap.run(3.0)
    new = (8, 36, 42, 132, 230, 241, 290, 291, 380, 441, 514, 12901, 12904)
    for msg_id in new:
        tap.command(MavCmd.REQUEST_MESSAGE, msg_id)
    tap.run(0.1)
    assert tap.acks() == [(MavCmd.REQUEST_MESSAGE, 0)] * len(new)


def test_set_and_get_message_interval_for_the_new_streams(tap):
    tap.run(3.0)
    tap.command(MavCmd.SET_MESSAGE_INTERVAL, 291, 100_000)  # ESC_STATUS at 10 Hz on this link only
    tap.command(MavCmd.SET_MESSAGE_INTERVAL, 36, -1)  # SERVO_OUTPUT_RAW off
    tap.command(MavCmd.GET_MESSAGE_INTERVAL, 380)  # TIME_ESTIMATE_TO_TARGET: PX4 configures 1 Hz
    tap.run(0.1)
    tap.clear()
    tap.run(2.0)
    gcs, api = tap.ids("gcs"), tap.ids("api")
    assert gcs[291] == pytest.approx(20, abs=1) and gcs[36] == 0
    assert api[291] == pytest.approx(20, abs=1) and api[36] == pytest.approx(20, abs=1)  # onboard defaults: 10 Hz
    tap.clear()
    tap.command(MavCmd.GET_MESSAGE_INTERVAL, 380)
    tap.command(MavCmd.SET_MESSAGE_INTERVAL, 411, 1_000_000)  # a message the emulator does not have
    tap.run(0.1)
    assert [(m.message_id, m.interval_us) for m in tap.messages("gcs", 244)] == [(380, 1_000_000)]
    assert tap.acks() == [(MavCmd.GET_MESSAGE_INTERVAL, 0), (MavCmd.SET_MESSAGE_INTERVAL, 4)]
