"""MAVLink 2 message signing on the wire, without state: the 13-byte signature block and its check.

As the MAVLink 2 signing specification defines it (mavlink.io, guide/message_signing; the C library's
mavlink_sign_packet and mavlink_signature_check in mavlink_helpers.h, which PX4 runs): a signed frame has the
MAVLINK_IFLAG_SIGNED bit (0x01) in its incompat flags (covered by the CRC like the rest of the header) and carries,
after the CRC, the link id (1 byte), a 48-bit timestamp (little endian, units of 10 us since 2015-01-01 00:00 UTC) and
the first 6 bytes of SHA-256(secret key + the frame from its magic byte through the timestamp).
"""

from __future__ import annotations

import hashlib
from typing import Final

MAGIC_V2: Final = 0xFD
IFLAG_SIGNED: Final = 0x01
SIGNATURE_BLOCK_LEN: Final = 13  # link id, timestamp, signature
SIGNATURE_LEN: Final = 6


def signature(key: bytes, signed_part: bytes | bytearray) -> bytes:
    """The 6 signature bytes of `signed_part` (magic byte through timestamp)."""
    return hashlib.sha256(key + signed_part).digest()[:SIGNATURE_LEN]


def sign_frame(frame: bytes, key: bytes, link_id: int, timestamp: int) -> bytes:
    """`frame` (a whole MAVLink 2 frame built with IFLAG_SIGNED set) with its signature block appended."""
    signed_part = frame + bytes((link_id & 0xFF,)) + timestamp.to_bytes(6, "little")
    return signed_part + signature(key, signed_part)


def is_signed(frame: bytes | bytearray) -> bool:
    """A MAVLink 2 frame whose header says it carries a signature block."""
    return len(frame) > SIGNATURE_BLOCK_LEN + 2 and frame[0] == MAGIC_V2 and bool(frame[2] & IFLAG_SIGNED)


def signature_block(frame: bytes | bytearray) -> tuple[int, int]:
    """(link id, timestamp) of a signed frame."""
    block = frame[-SIGNATURE_BLOCK_LEN:]
    return block[0], int.from_bytes(block[1:7], "little")


def signature_matches(frame: bytes | bytearray, key: bytes) -> bool:
    """Whether a signed frame's signature is the one `key` gives."""
    return signature(key, frame[:-SIGNATURE_LEN]) == frame[-SIGNATURE_LEN:]
