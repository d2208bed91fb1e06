"""`joyfly fly --signing-key FILE`: MAVLink 2 signing on joyfly's side of the link, with pymavlink's signing.

A vehicle that signs (PX4 main with a key provisioned; `sitl-emu serve --signing-key`) refuses every unsigned message
but a few (HEARTBEAT, RADIO_STATUS, ADSB_VEHICLE, COLLISION: mavlink_sign_control.cpp), so joyfly signs everything
it sends with the same key, and takes from the vehicle only what is signed with it (its heartbeat also unsigned, so
that a vehicle without the key is still found, and `--setup-signing` can give it the key with SETUP_SIGNING, as
QGroundControl does: PX4 accepts it from any link while it has no key, and signed with the current key after).

The key file is read by px4common/signing_key.py, as `sitl-emu serve --signing-key` reads it.
"""

from __future__ import annotations

import time
from typing import Any

from px4common.signing_key import timestamp_from_unix_us

HEARTBEAT_ID = 0
LINK_ID = 0


def wall_timestamp() -> int:
    """Now as a signing timestamp (10 us since 2015): a vehicle refuses a new stream more than a minute behind."""
    return timestamp_from_unix_us(time.time_ns() // 1000)


def sign_with(mav: Any, key: bytes) -> None:
    """Make pymavlink's MAVLink object `mav` sign what it sends with `key` and check what it parses."""
    signing = mav.signing
    signing.secret_key = key
    signing.link_id = LINK_ID
    signing.sign_outgoing = True
    signing.timestamp = wall_timestamp()
    signing.allow_unsigned_callback = _unsigned_heartbeat


def keep_up(mav: Any) -> None:
    """Move the signing timestamp up to the wall clock (pymavlink counts one per message only), so that a vehicle that
    restarts and forgets our stream still takes the next message for a fresh one."""
    mav.signing.timestamp = max(mav.signing.timestamp, wall_timestamp())


def _unsigned_heartbeat(mav: Any, msg_id: int) -> bool:
    return msg_id == HEARTBEAT_ID
