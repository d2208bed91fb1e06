"""`serve --signing-key FILE` and the signing key each vehicle keeps in its storage root (sitl_emu/mavlink/signing.py).

PX4 SITL keeps its key in `mavlink/mavlink-signing-key.bin` under its working directory, and so does `serve` (vehicle N
of a --count: `mavlink/mavlink-signing-key-N.bin`, as its parameters file). At start each vehicle loads its stored key;
`--signing-key FILE` provisions FILE's key instead, as a SETUP_SIGNING would (stored, then used): the vehicle starts
signed. FILE holds the 32-byte key, as 64 hexadecimal digits or as the raw bytes (PX4's own 40-byte key file, key then
timestamp, is read too); joyfly's `--signing-key` reads the same files (joyfly/link/signing_key.py).
"""

from __future__ import annotations

import string
import time
from collections.abc import Sequence
from pathlib import Path

from sitl_emu.cli.options import UsageProblem
from sitl_emu.mavlink.signing import KEY_FILE, TIMESTAMP_LEN
from sitl_emu.mavlink.wire.signing import KEY_LEN
from sitl_emu.params.store import instance_path
from sitl_emu.runtime.node import VehicleNode


def read_signing_key(path: Path) -> bytes:
    """The 32-byte key in `path`; UsageProblem with one sentence if there is none."""
    try:
        data = path.read_bytes()
    except OSError as err:
        raise UsageProblem(f"--signing-key {path}: cannot read it ({err.strerror or err}).") from None
    text = data.strip()
    if len(text) == 2 * KEY_LEN and all(chr(c) in string.hexdigits for c in text):
        return bytes.fromhex(text.decode("ascii"))
    if len(data) in (KEY_LEN, KEY_LEN + TIMESTAMP_LEN):
        return data[:KEY_LEN]
    raise UsageProblem(f"--signing-key {path}: not a MAVLink signing key; the file must hold 32 bytes, as 64 "
                       f"hexadecimal digits or raw (e.g. `openssl rand -hex 32 > {path.name}`).")


def wall_clock_us() -> int:
    """The Unix time in us: PX4 signs with its real-time clock (CLOCK_REALTIME), whatever the simulation speed."""
    return time.time_ns() // 1000


def attach_signing(nodes: Sequence[VehicleNode], first_instance: int, key: bytes | None) -> list[str]:
    """Give each vehicle its key file and the wall clock, load its stored key or provision `key`; warnings."""
    warnings: list[str] = []
    for i, node in enumerate(nodes):
        signing = node.signing
        signing.key_file = instance_path(KEY_FILE, first_instance + i, first_instance)
        signing.wall_clock_us = wall_clock_us
        if key is None:
            warning = signing.load()
            if warning:
                warnings.append(warning)
            continue
        try:
            signing.provision(key)
        except OSError as err:
            raise UsageProblem(f"--signing-key: {err}; run serve in a directory it can write.") from None
    return warnings
