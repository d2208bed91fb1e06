"""QGroundControl's initial connect sequence (src/Vehicle/InitialConnectStateMachine.cc, ComponentInformationManager,
ParameterManager's hash check) run by a pymavlink client against a real vehicle node in lockstep:

AUTOPILOT_VERSION; COMPONENT_METADATA and the general metadata over MAVLink FTP (xz, CRC checked), then each file it
lists (parameters, events); AVAILABLE_MODES; the parameter list checked against the parameter metadata and the
_HASH_CHECK value recomputed as QGC does (its cache in name order, the parameters the metadata marks volatile left
out); mission, fence and rally download; and every EVENT received decoded with the served events metadata. With the
events metadata declaring the health_and_arming_check protocol, QGC asks for the report (MAV_CMD_RUN_PREARM_CHECKS,
as its own vehicle tests do) and reads it as libevents' parser does: can_arm of the mode group its HEARTBEAT's custom
mode maps to (navigation_mode_groups), the checks that affect that group, the health components' flags.
"""

from __future__ import annotations

import json
import lzma
import struct
import zlib

import pytest
from support.events_client import EventsDecoder, HealthAndArmingChecks, extra_of
from support.fakes import HOME, Harness
from support.ftp_client import FtpClient

from sitl_emu.mavlink.endpoint import load_handler_classes
from sitl_emu.px4 import MavCmd
from sitl_emu.vehicle.vehicle import Vehicle

MSG_AUTOPILOT_VERSION, MSG_AVAILABLE_MODES, MSG_COMPONENT_METADATA = 148, 435, 397
COMP_METADATA_TYPE_PARAMETER, COMP_METADATA_TYPE_EVENTS = 1, 4


def _crc32(data: bytes) -> int:
    """MAVLink's CRC32 as PX4's generators and QGC compute it (no inversions)."""
    return zlib.crc32(data, 0xFFFFFFFF) ^ 0xFFFFFFFF


class Qgc:
    def __init__(self, h: Harness) -> None:
        self.h = h
        self.ftp = FtpClient(h)

    def request(self, msg_id: int, param2: float = 0.0) -> list:
        start = len(self.h.gcs.received)
        self.h.gcs.command_long(MavCmd.REQUEST_MESSAGE, msg_id, param2)
        self.h.run(0.05)
        return self.h.gcs.received[start:]

    def download(self, uri: str) -> bytes:
        assert uri.startswith("mftp://")
        return lzma.decompress(self.ftp.read_file(b"/" + uri.removeprefix("mftp://").encode()))

    def param_list(self) -> dict[str, object]:
        self.h.gcs.send(self.h.gcs.mav.param_request_list_encode(1, 1))
        start = len(self.h.gcs.received)
        self.h.run(2.0)
        return {m.param_id: m for m in self.h.gcs.received[start:] if m.get_type() == "PARAM_VALUE"}

    def plan_count(self, mission_type: int) -> int:
        start = len(self.h.gcs.received)
        self.h.gcs.send(self.h.gcs.mav.mission_request_list_encode(1, 1, mission_type))
        self.h.run(0.05)
        (count,) = [m for m in self.h.gcs.received[start:] if m.get_type() == "MISSION_COUNT"]
        assert count.mission_type == mission_type
        self.h.gcs.send(self.h.gcs.mav.mission_ack_encode(1, 1, 0, mission_type))
        return count.count


@pytest.fixture
def h():
    harness = Harness(Vehicle(home=HOME), handler_classes=None)  # the node's default protocols, as serve has them
    harness.gcs.heartbeat()
    harness.io()
    yield harness
    harness.close()


def test_qgc_connects_downloads_the_metadata_and_decodes_every_event(h):
    qgc = Qgc(h)
    h.gcs.command_long(MavCmd.COMPONENT_ARM_DISARM, 1)  # refused before the estimator is ready: an event
    h.run(2.5)
    # 1. AUTOPILOT_VERSION
    assert [m for m in qgc.request(MSG_AUTOPILOT_VERSION) if m.get_type() == "AUTOPILOT_VERSION"]
    # 2. component metadata: COMPONENT_METADATA, the general file, then what it lists
    replies = [x for x in map(extra_of, qgc.request(MSG_COMPONENT_METADATA)) if x and x[0] == MSG_COMPONENT_METADATA]
    (meta,) = [fields for _, fields in replies]
    uri = meta["uri"].rstrip(b"\0").decode()
    assert uri == "mftp://etc/extras/component_general.json.xz"
    general_bytes = qgc.download(uri)
    assert _crc32(general_bytes) == meta["file_crc"]
    general = json.loads(general_bytes)
    files = {}
    for entry in general["metadataTypes"]:
        data = qgc.download(entry["uri"])
        assert _crc32(data) == entry["fileCrc"], entry["uri"]
        files[entry["type"]] = json.loads(data)
    assert set(files) == {COMP_METADATA_TYPE_PARAMETER, COMP_METADATA_TYPE_EVENTS}
    # 3. AVAILABLE_MODES (param2 0: all of them)
    modes = [m for m in qgc.request(MSG_AVAILABLE_MODES, 0) if m.get_type() == "AVAILABLE_MODES"]
    assert modes and len(modes) == modes[0].number_modes
    # 4. parameters: every listed one described by the metadata, with its type; QGC's hash check holds
    values = qgc.param_list()
    hash_check = values.pop("_HASH_CHECK")
    described = {p["name"]: p for p in files[COMP_METADATA_TYPE_PARAMETER]["parameters"]}
    assert set(values) == set(described)
    for name, value in values.items():
        assert (value.param_type == 6) == (described[name]["type"] == "Int32"), name
    assert _qgc_hash(values, described) == struct.unpack("<I", struct.pack("<f", hash_check.param_value))[0]
    # 5. mission, fence and rally download
    assert [qgc.plan_count(t) for t in (0, 1, 2)] == [0, 0, 0]
    # 6. the health and arming check report, read as QGC does
    metadata = files[COMP_METADATA_TYPE_EVENTS]
    px4 = metadata["components"]["1"]
    assert "health_and_arming_check" in px4["supported_protocols"]
    report = _report_after(h, qgc, MavCmd.RUN_PREARM_CHECKS, EventsDecoder(metadata))
    (heartbeat,) = h.gcs.of_type("HEARTBEAT")[-1:]
    (group,) = [int(g) for g, modes in px4["navigation_mode_groups"]["groups"].items()
                if heartbeat.custom_mode in modes]
    assert group == 4  # Hold (nav_state 4)
    assert report.can_arm[group] and report.checks_for(group) == ["No manual control input"]
    assert report.components["remote_control"] == {"arm_error": False, "arm_warning": True, "present": False,
                                                   "error": False, "warning": False}
    assert report.components["gyro"]["present"] and not report.components["gyro"]["arm_error"]
    assert not report.can_arm[3] and "No valid mission available" in report.checks_for(3)  # Mission: none uploaded
    # events: each one received decodes with the served metadata
    h.gcs.command_long(MavCmd.COMPONENT_ARM_DISARM, 1)
    h.run(0.1)
    h.gcs.command_long(MavCmd.COMPONENT_ARM_DISARM, 0)
    h.run(0.1)
    decoder = EventsDecoder(metadata)
    events = [fields for msg_id, fields in filter(None, map(extra_of, h.gcs.received)) if msg_id == 410]
    decoded = [decoder.parse(e["id"], e["arguments"]) for e in events]
    assert None not in decoded
    assert [e.message for e in decoded if e is not None and e.group == "default"] == [
        "Arming denied: Resolve system health failures first", "Armed by external command",
        "Disarmed by external command"]


def _report_after(h, qgc, command, decoder) -> object:
    """Send `command`, read the events that follow with libevents' health and arming checks parser."""
    start = len(h.gcs.received)
    h.gcs.command_long(command)
    h.run(0.05)
    parser = HealthAndArmingChecks()
    done = [parser.handle(decoder.parse(f["id"], f["arguments"], f["log_levels"]))
            for msg_id, f in filter(None, map(extra_of, h.gcs.received[start:])) if msg_id == 410]
    assert done and done[-1] and parser.results is not None
    return parser.results


def _qgc_hash(values: dict, described: dict) -> int:
    """ParameterManager::_tryCacheHashLoad: over the cache in name order, volatile parameters skipped, each name's
    bytes then the value's four bytes as received (PARAM_VALUE carries an int32 bytewise in its float)."""
    crc = 0
    for name in sorted(values):
        if described[name].get("volatile"):
            continue
        raw = struct.pack("<f", values[name].param_value)
        crc = zlib.crc32(raw, zlib.crc32(name.encode(), crc ^ 0xFFFFFFFF)) ^ 0xFFFFFFFF
    return crc


def test_the_events_and_ftp_protocols_are_on_every_nodes_default_list():
    names = {cls.__name__ for cls in load_handler_classes()}
    assert {"EventsProtocol", "FtpProtocol"} <= names


def test_a_failsafe_notice_decodes_with_the_downloaded_metadata(h):
    """framework.cpp notifyUser: offboard setpoints stop, Position cannot run without sticks, the fallback is
    NAV_RCL_ACT's Return; QGC shows the event's message, made from the metadata it downloaded."""
    qgc = Qgc(h)
    h.run(2.5)
    (meta,) = [f for x in map(extra_of, qgc.request(MSG_COMPONENT_METADATA)) if x and x[0] == 397 for f in [x[1]]]
    general = json.loads(qgc.download(meta["uri"].rstrip(b"\0").decode()))
    (events_uri,) = [e["uri"] for e in general["metadataTypes"] if e["type"] == COMP_METADATA_TYPE_EVENTS]
    decoder = EventsDecoder(json.loads(qgc.download(events_uri)))
    h.gcs.command_long(MavCmd.COMPONENT_ARM_DISARM, 1)
    h.gcs.command_long(MavCmd.NAV_TAKEOFF)
    h.run(8.0)
    start = len(h.gcs.received)
    h.gcs.send(h.gcs.mav.set_position_target_local_ned_encode(0, 1, 1, 1, 0b110111111000, 0, 0, -2.5, *[0] * 8))
    h.gcs.command_long(MavCmd.DO_SET_MODE, 1, 6, 0)  # OFFBOARD, then no more setpoints
    h.run(3.0)
    notices = [decoder.decode(f["id"], f["arguments"]) for msg_id, f in filter(None, map(extra_of,
               h.gcs.received[start:])) if msg_id == 410]
    assert ("commander_failsafe_enter_generic", "Failsafe activated: switching to RTL") \
        in notices
