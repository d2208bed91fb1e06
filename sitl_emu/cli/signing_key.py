"""`serve --signing-key FILE` and the signing key each vehicle keeps in its storage root (sitl_emu/mavlink/signing.py).

PX4 SITL keeps its key in `mavlink/mavlink-signing-key.bin` under its working directory, and so does `serve` (vehicle N
of a --count: `mavlink/mavlink-signing-key-N.bin`, as its parameters file). At start each vehicle loads its stored key;
`--signing-key FILE` provisions FILE's key instead, as a SETUP_SIGNING would (stored, then used): the vehicle starts
signed. FILE holds the 32-byte key, as 64 hexadecimal digits or as the raw bytes (PX4's own 40-byte key file, key then
timestamp, is read too: px4common/signing_key.py reads it, for joyfly's `--signing-key` as well).
"""

from __future__ import annotations

import time
from collections.abc import Sequence

from sitl_emu.cli.options import UsageProblem
from sitl_emu.mavlink.signing import KEY_FILE
from sitl_emu.params.store import instance_path
from sitl_emu.runtime.node import VehicleNode


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
