"""MAVLink 2 signing as PX4 main does it: one secret key for all of a vehicle's links, kept in its storage root.

PX4 main (src/modules/mavlink/mavlink_sign_control.cpp and mavlink_signing_storage.cpp, since PX4 PR #26894
"align signing with MAVLink spec", 2026-03) has no MAV_SIGN_CFG parameter any more (nor does the parameter list
recorded from PX4 main SITL, ../shared/reference/px4-params.json): signing is on exactly when a key is provisioned.
- The key lives in `mavlink/mavlink-signing-key.bin` under the storage root: 32 key bytes, then the 8-byte
  little-endian timestamp. Loaded at start; a key of all zeros with timestamp 0 means no key.
- SETUP_SIGNING sets it at run time, on any link: unsigned when no key is set (the parser accepts everything then),
  signed with the current key once one is (the check below refuses anything else). An all-zero key and timestamp
  turns signing off, and only in a signed message. Refused while armed ("MAVLink signing: rejected while armed").
  The timestamp kept is the largest of the one asked for, the current one (same key), the stored one (same key) and
  the wall clock's; the file is written before the key is used.
- With a key, every outgoing message is signed (link id: PX4's mavlink instance, GCS 0 and API 1 in SITL), and an
  incoming one is accepted only if signed with the key, except PX4's short list of messages accepted unsigned
  (HEARTBEAT, RADIO_STATUS, ADSB_VEHICLE, COLLISION). A signed message is checked as the C library's
  mavlink_signature_check does: the signature first, then per (system, component, link id) stream a timestamp
  greater than the stream's last one (a replay is refused), and a new stream's first timestamp no more than one
  minute behind the vehicle's signing timestamp (at most 16 streams); an accepted timestamp ahead of the vehicle's
  moves it on.
- The outgoing timestamp is the vehicle's signing timestamp, which follows the wall clock (PX4's checkpoint sets it
  from CLOCK_REALTIME) and goes up by one per message sent.
"""

from __future__ import annotations

import enum
import logging
import os
from collections.abc import Callable
from pathlib import Path
from typing import Final

from px4common.signing_key import KEY_LEN, timestamp_from_unix_us
from sitl_emu.mavlink.wire import signing as wire

log = logging.getLogger(__name__)

KEY_FILE: Final = Path("mavlink") / "mavlink-signing-key.bin"  # under the storage root (MAVLINK_SECRET_FILE)
TIMESTAMP_LEN: Final = 8
# mavlink_sign_control.cpp unsigned_messages: HEARTBEAT, RADIO_STATUS, ADSB_VEHICLE, COLLISION
UNSIGNED_ACCEPTED: Final = frozenset({0, 109, 246, 247})
NEW_STREAM_MAX_AGE: Final = 6_000_000  # one minute in signing-timestamp units (10 us)
MAX_STREAMS: Final = 16  # MAVLINK_MAX_SIGNING_STREAMS
ARMED_TEXT: Final = "MAVLink signing: rejected while armed"
NO_KEY: Final = bytes(KEY_LEN)


class SetupResult(enum.Enum):
    KEY_ACCEPTED = "key accepted"
    SIGNING_DISABLED = "signing disabled"
    BLANK_KEY_REJECTED = "blank key rejected: the message must be signed"
    REJECTED_ARMED = "rejected while armed"
    STORAGE_ERROR = "the key file cannot be written"


class MavlinkSigning:
    """A vehicle's signing state, shared by its links: the key, the signing timestamp and the incoming streams.

    `key_file` (None: kept in memory only) is where the key persists; `wall_clock_us` gives the Unix time in us
    (the runner's clock; None: the simulated Unix time each call is given).
    """

    def __init__(self, key_file: Path | None = None, wall_clock_us: Callable[[], int] | None = None) -> None:
        self.key_file = key_file
        self.wall_clock_us = wall_clock_us
        self.key: bytes | None = None
        self.timestamp = 0
        self._streams: dict[tuple[int, int, int], int] = {}

    @property
    def active(self) -> bool:
        return self.key is not None

    # --- the key -------------------------------------------------------------------------------------------------
    def load(self, now_unix_us: int = 0) -> str | None:
        """Read the key file if there is one; a warning sentence if it cannot be used."""
        if self.key_file is None or not self.key_file.exists():
            return None
        try:
            data = self.key_file.read_bytes()
        except OSError as err:
            return f"cannot read the MAVLink signing key {self.key_file}: {err.strerror or err}"
        if len(data) < KEY_LEN + TIMESTAMP_LEN:
            return f"{self.key_file} is not a MAVLink signing key file (40 bytes): signing stays off"
        stored = int.from_bytes(data[KEY_LEN:KEY_LEN + TIMESTAMP_LEN], "little")
        self._apply(data[:KEY_LEN], max(stored, self._wall(now_unix_us)) if _enabled(data, stored) else 0)
        return None

    def provision(self, key: bytes, now_unix_us: int = 0) -> None:
        """Start signed with `key` (`serve --signing-key`): as a SETUP_SIGNING with timestamp 0 would; OSError if
        the key file cannot be written."""
        if self._store(self._reconciled(key, 0, now_unix_us)) is not SetupResult.KEY_ACCEPTED:
            raise OSError(f"cannot write {self.key_file}")

    def setup(self, key: bytes, initial_timestamp: int, signed: bool, armed: bool, now_unix_us: int) -> SetupResult:
        """SETUP_SIGNING (mavlink_sign_control.cpp check_for_signing)."""
        if armed:
            return SetupResult.REJECTED_ARMED
        if initial_timestamp == 0 and key == NO_KEY:
            if not self.active:
                return SetupResult.SIGNING_DISABLED
            if not signed:
                return SetupResult.BLANK_KEY_REJECTED
            result = self._store((NO_KEY, 0))
            return SetupResult.SIGNING_DISABLED if result is SetupResult.KEY_ACCEPTED else result
        return self._store(self._reconciled(key, initial_timestamp, now_unix_us))

    def _reconciled(self, key: bytes, timestamp: int, now_unix_us: int) -> tuple[bytes, int]:
        """mavlink_signing_storage.cpp reconcile_and_replace: never go back in time for the same key."""
        if key == self.key:
            timestamp = max(timestamp, self.timestamp)
        stored = self._read_stored()
        if stored is not None and stored[0] == key:
            timestamp = max(timestamp, stored[1])
        return key, max(timestamp, self._wall(now_unix_us))

    def _read_stored(self) -> tuple[bytes, int] | None:
        try:
            data = self.key_file.read_bytes() if self.key_file is not None else b""
        except OSError:
            return None
        if len(data) < KEY_LEN + TIMESTAMP_LEN:
            return None
        return data[:KEY_LEN], int.from_bytes(data[KEY_LEN:KEY_LEN + TIMESTAMP_LEN], "little")

    def _store(self, state: tuple[bytes, int]) -> SetupResult:
        """Write the file (atomically, mode 600), then use the key."""
        key, timestamp = state
        if self.key_file is not None:
            try:
                _write_atomic(self.key_file, key + timestamp.to_bytes(TIMESTAMP_LEN, "little"))
            except OSError as err:
                log.error("cannot store the MAVLink signing key in %s: %s", self.key_file, err)
                return SetupResult.STORAGE_ERROR
        self._apply(key, timestamp)
        return SetupResult.KEY_ACCEPTED

    def _apply(self, key: bytes, timestamp: int) -> None:
        enabled = _enabled(key, timestamp)
        self.key = key if enabled else None
        self.timestamp = timestamp if enabled else 0

    def _wall(self, now_unix_us: int) -> int:
        unix_us = self.wall_clock_us() if self.wall_clock_us is not None else now_unix_us
        return timestamp_from_unix_us(unix_us)

    # --- messages ------------------------------------------------------------------------------------------------
    def sign(self, frame: bytes, link_id: int, now_unix_us: int) -> bytes:
        """A frame built with IFLAG_SIGNED, signed with the next timestamp (only while active)."""
        assert self.key is not None
        self.timestamp = max(self.timestamp + 1, self._wall(now_unix_us))
        return wire.sign_frame(frame, self.key, link_id, self.timestamp)

    def accept(self, frame: bytes | bytearray, msg_id: int, sysid: int, compid: int) -> bool:
        """Whether an incoming frame passes (always, without a key)."""
        key = self.key
        if key is None:
            return True
        if not wire.is_signed(frame):
            return msg_id in UNSIGNED_ACCEPTED
        if not wire.signature_matches(frame, key):
            return msg_id in UNSIGNED_ACCEPTED
        return self._fresh(frame, sysid, compid)

    def _fresh(self, frame: bytes | bytearray, sysid: int, compid: int) -> bool:
        """The C library's stream check: no replay, no new stream more than a minute old."""
        link_id, timestamp = wire.signature_block(frame)
        stream = (sysid, compid, link_id)
        last = self._streams.get(stream)
        if last is None:
            if len(self._streams) >= MAX_STREAMS or timestamp + NEW_STREAM_MAX_AGE < self.timestamp:
                return False
        elif timestamp <= last:
            return False
        self._streams[stream] = timestamp
        self.timestamp = max(self.timestamp, timestamp)
        return True


def _enabled(key: bytes, timestamp: int) -> bool:
    """mavlink_signing_storage.cpp is_enabled: a key that is not all zeros, or a timestamp that is not 0."""
    return timestamp != 0 or key != NO_KEY


def _write_atomic(path: Path, data: bytes) -> None:
    path.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp")
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    try:
        os.write(fd, data)
        os.fsync(fd)
    finally:
        os.close(fd)
    os.replace(tmp, path)
