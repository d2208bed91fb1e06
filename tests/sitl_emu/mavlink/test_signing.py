"""MAVLink 2 signing as PX4 main does it (mavlink_sign_control.cpp): with a key, a client without it cannot arm,
change a parameter or upload a mission; with it everything works; replayed or stale frames are ignored; the vehicle
signs what it sends; SETUP_SIGNING sets, persists and clears the key. pymavlink's own signing on the client side."""

from __future__ import annotations

import hashlib
import math
from pathlib import Path

import pytest
from pymavlink.dialects.v20 import development as dialect
from support.fakes import HOME, Client, Harness

from px4common.signing_key import timestamp_from_unix_us
from sitl_emu.mavlink.signing import KEY_FILE, MavlinkSigning
from sitl_emu.mavlink.wire.signing import sign_frame, signature_matches
from sitl_emu.px4 import MavCmd, MavResult
from sitl_emu.vehicle.vehicle import Vehicle

EPOCH_US = 1_700_000_000_000_000
KEY = hashlib.sha256(b"joyfly test key").digest()
OTHER_KEY = hashlib.sha256(b"someone else").digest()


def _sign(client: Client, key: bytes, link_id: int = 0, timestamp_us: int = EPOCH_US) -> Client:
    """pymavlink's signing on a test client: every message it sends from now on is signed with `key`."""
    client.mav.signing.secret_key = key
    client.mav.signing.link_id = link_id
    client.mav.signing.sign_outgoing = True
    client.mav.signing.timestamp = timestamp_from_unix_us(timestamp_us)
    return client


@pytest.fixture
def h(tmp_path: Path):
    harness = Harness(Vehicle(home=HOME), handler_classes=None, epoch_unix_us=EPOCH_US)
    harness.node.signing.key_file = tmp_path / KEY_FILE
    harness.node.signing.provision(KEY, EPOCH_US)
    yield harness
    harness.close()


def _ready(h: Harness) -> None:
    h.api.heartbeat()
    h.gcs.heartbeat()
    h.run(2.5)


def _acks(client: Client, command: int) -> list[int]:
    return [a.result for a in client.of_type("COMMAND_ACK") if a.command == command]


def _param(client: Client, name: bytes, value: float) -> None:
    client.send(client.mav.param_set_encode(1, 1, name, value, dialect.MAV_PARAM_TYPE_REAL32))


def _upload_starts(h: Harness, client: Client) -> bool:
    client.send(client.mav.mission_count_encode(1, 1, 1, 0))
    h.run(0.2)
    return bool(client.of_type("MISSION_REQUEST_INT") or client.of_type("MISSION_REQUEST"))


def test_a_client_without_the_key_can_neither_arm_nor_set_a_parameter_nor_upload_a_mission(h):
    _ready(h)
    h.api.command_long(MavCmd.COMPONENT_ARM_DISARM, 1.0)
    _param(h.api, b"MPC_XY_VEL_MAX", 7.0)
    h.run(0.3)
    assert not h.vehicle.snapshot().armed and not _acks(h.api, MavCmd.COMPONENT_ARM_DISARM)
    assert h.vehicle.params.get("MPC_XY_VEL_MAX") != 7.0 and not h.api.of_type("PARAM_VALUE")
    assert not _upload_starts(h, h.api)
    _sign(h.gcs, OTHER_KEY)  # signed, but with another key: refused too
    h.gcs.command_long(MavCmd.COMPONENT_ARM_DISARM, 1.0)
    h.run(0.3)
    assert not h.vehicle.snapshot().armed and not _acks(h.gcs, MavCmd.COMPONENT_ARM_DISARM)
    assert h.node.api.stats.rx_signing_rejected >= 3 and h.node.gcs.stats.rx_signing_rejected >= 1


def test_with_the_key_everything_works_and_the_vehicle_signs_what_it_sends(h):
    _sign(h.api, KEY)
    _ready(h)
    _param(h.api, b"MPC_XY_VEL_MAX", 7.0)
    assert _upload_starts(h, h.api)
    h.api.command_long(MavCmd.COMPONENT_ARM_DISARM, 1.0)
    h.run(0.3)
    assert _acks(h.api, MavCmd.COMPONENT_ARM_DISARM) == [MavResult.ACCEPTED] and h.vehicle.snapshot().armed
    assert h.vehicle.params.get("MPC_XY_VEL_MAX") == pytest.approx(7.0)
    # every frame the vehicle sent is signed with the key, on link id 1 (the API link is PX4's mavlink instance 1)
    frames = [bytes(m.get_msgbuf()) for m in h.api.of_type("HEARTBEAT") + h.api.of_type("COMMAND_ACK")]
    assert frames and all(f[2] & 1 and f[-13] == 1 and signature_matches(f, KEY) for f in frames)
    assert all(_checker().parse_buffer(f)[0].get_type() != "BAD_DATA" for f in frames)  # pymavlink agrees
    stamps = [int.from_bytes(f[-12:-6], "little") for f in frames]
    assert stamps[0] >= timestamp_from_unix_us(EPOCH_US)  # the vehicle's clock, in 10 us since 2015


def _checker() -> dialect.MAVLink:
    checker = dialect.MAVLink(None)
    checker.signing.secret_key = KEY
    return checker


def test_unsigned_heartbeats_are_still_heard_as_px4_allows(h):
    h.gcs.heartbeat()  # unsigned: on PX4's allow-list (HEARTBEAT, RADIO_STATUS, ADSB_VEHICLE, COLLISION)
    h.run(0.1)
    assert h.node.gcs.gcs_connected() and h.node.gcs.stats.rx_signing_rejected == 0


def test_a_replayed_datagram_is_ignored(h):
    _sign(h.api, KEY)
    _ready(h)
    arm = h.api.mav.command_long_encode(1, 1, MavCmd.COMPONENT_ARM_DISARM, 0, 1, 0, 0, 0, 0, 0, 0).pack(h.api.mav)
    h.api.send_raw(bytes(arm))
    h.run(0.2)
    h.api.command_long(MavCmd.COMPONENT_ARM_DISARM, 0.0)  # disarm, signed with a newer timestamp
    h.run(0.2)
    assert not h.vehicle.snapshot().armed
    h.api.send_raw(bytes(arm))  # the same arm datagram again: its timestamp is not newer than the stream's last
    h.run(0.3)
    assert not h.vehicle.snapshot().armed
    assert _acks(h.api, MavCmd.COMPONENT_ARM_DISARM) == [MavResult.ACCEPTED, MavResult.ACCEPTED]


def test_a_new_stream_more_than_a_minute_behind_is_refused(h):
    _sign(h.api, KEY, timestamp_us=EPOCH_US - 61_000_000)
    _ready(h)
    h.api.command_long(MavCmd.COMPONENT_ARM_DISARM, 1.0)
    h.run(0.3)
    assert not h.vehicle.snapshot().armed
    _sign(h.gcs, KEY, timestamp_us=EPOCH_US - 50_000_000)  # within the minute: accepted
    h.gcs.command_long(MavCmd.COMPONENT_ARM_DISARM, 1.0)
    h.run(0.3)
    assert h.vehicle.snapshot().armed


def _setup_signing(client: Client, key: bytes, timestamp: int = 0) -> None:
    client.send(client.mav.setup_signing_encode(1, 1, list(key), timestamp))


def test_setup_signing_sets_the_key_unsigned_once_persists_it_and_clears_it_only_signed(tmp_path: Path):
    h = Harness(Vehicle(home=HOME), handler_classes=None, epoch_unix_us=EPOCH_US)
    key_file = tmp_path / KEY_FILE
    h.node.signing.key_file = key_file
    try:
        _ready(h)
        _setup_signing(h.api, KEY, 123)  # no key yet: accepted unsigned, from any link
        h.run(0.1)
        assert h.node.signing.active and key_file.read_bytes()[:32] == KEY
        stored_ts = int.from_bytes(key_file.read_bytes()[32:40], "little")
        assert stored_ts >= timestamp_from_unix_us(EPOCH_US)  # never behind the vehicle's clock
        assert (key_file.stat().st_mode & 0o777) == 0o600
        h.api.command_long(MavCmd.COMPONENT_ARM_DISARM, 1.0)  # unsigned from now on: refused
        _setup_signing(h.api, bytes(32))  # a blank key, unsigned: refused
        h.run(0.3)
        assert not h.vehicle.snapshot().armed and h.node.signing.active
        # the key survives a restart: a fresh signing state loads it from the file
        reloaded = MavlinkSigning(key_file)
        assert reloaded.load(EPOCH_US) is None and reloaded.key == KEY
        _sign(h.gcs, KEY)
        _setup_signing(h.gcs, bytes(32))  # a blank key, signed with the current one: signing off
        h.run(0.1)
        assert not h.node.signing.active and key_file.read_bytes() == bytes(40)
        h.api.command_long(MavCmd.COMPONENT_ARM_DISARM, 1.0)
        h.run(0.3)
        assert h.vehicle.snapshot().armed
    finally:
        h.close()


def test_setup_signing_is_refused_while_armed(h):
    _sign(h.api, KEY)
    _ready(h)
    h.api.command_long(MavCmd.COMPONENT_ARM_DISARM, 1.0)
    h.run(0.2)
    h.api.heartbeat()  # texts wait for a ground station heard in the last 2.5 s
    _setup_signing(h.api, OTHER_KEY)
    h.run(0.2)
    assert h.node.signing.key == KEY
    assert "MAVLink signing: rejected while armed" in [t.text for t in h.api.of_type("STATUSTEXT")]


def test_sign_frame_is_what_pymavlink_signs():
    mav = dialect.MAVLink(None, srcSystem=1, srcComponent=1)
    mav.signing.secret_key, mav.signing.sign_outgoing, mav.signing.link_id = KEY, True, 3
    mav.signing.timestamp = 987_654_321
    msg = mav.attitude_encode(1, 0.1, -0.2, math.pi, 0, 0, 0)
    theirs = bytes(msg.pack(mav))
    unsigned = theirs[:-13]  # the frame pymavlink signed: header (with the signed flag) through CRC
    assert sign_frame(unsigned, KEY, 3, 987_654_321) == theirs
