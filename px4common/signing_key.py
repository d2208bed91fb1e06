"""The MAVLink 2 signing key file, as both programs read it: `sitl-emu serve --signing-key FILE` provisions its
vehicles with the key, `joyfly fly --signing-key FILE` signs with it, so one file serves both ends of a link.

FILE holds the 32-byte secret key as 64 hexadecimal digits (white space around them is ignored) or as the raw bytes;
PX4's own key file (mavlink/mavlink-signing-key.bin, written by src/modules/mavlink/mavlink_sign_control.cpp: the key,
then the 8-byte timestamp) is read too. Anything else is refused in one sentence that says how to make a key.
"""

from __future__ import annotations

import string
from pathlib import Path

KEY_LEN = 32  # MAVLink 2's secret key (mavlink_signing_t.secret_key)
PX4_KEY_FILE_LEN = KEY_LEN + 8  # PX4's file: the key, then the uint64 timestamp
EPOCH_2015_UNIX_US = 1_420_070_400_000_000  # signing timestamps count 10 us from 2015-01-01 (MAVLink 2 signing)
TIMESTAMP_MAX = (1 << 48) - 1  # the signature block's 48-bit timestamp


def timestamp_from_unix_us(unix_us: int) -> int:
    """The signing timestamp (10 us since 2015) of a Unix time in microseconds; 0 before 2015."""
    return min(max(unix_us - EPOCH_2015_UNIX_US, 0) // 10, TIMESTAMP_MAX)


class SigningKeyError(Exception):
    """The key file cannot be used; str() is one sentence naming the file and what to do."""


def read_signing_key(path: str | Path) -> bytes:
    """The 32-byte key in `path`; SigningKeyError if it cannot be read or holds no key."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as err:
        raise SigningKeyError(f"--signing-key {path}: cannot read it ({err.strerror or err}).") from None
    text = data.strip()
    if len(text) == 2 * KEY_LEN and all(chr(c) in string.hexdigits for c in text):
        return bytes.fromhex(text.decode("ascii"))
    if len(data) in (KEY_LEN, PX4_KEY_FILE_LEN):
        return data[:KEY_LEN]
    raise SigningKeyError(f"--signing-key {path}: not a MAVLink signing key; the file must hold 32 bytes, as 64 "
                          f"hexadecimal digits or raw (e.g. `openssl rand -hex 32 > {path.name}`).")
