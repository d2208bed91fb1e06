"""Component metadata as PX4 serves it (QGroundControl's second connect step, ComponentInformationManager).

- REQUEST_MESSAGE(COMPONENT_METADATA, 397) is answered with the general metadata's URI and CRC
  (src/modules/mavlink/streams/COMPONENT_METADATA.hpp: "mftp://etc/extras/component_general.json.xz" and
  component_information::component_general_crc); PX4 main has no COMPONENT_INFORMATION (395) stream any more, so
  that request is DENIED as before.
- The general metadata (src/lib/component_information/generate_component_general.py): {"version": 1,
  "metadataTypes": [{type, uri, fileCrc, uriFallback}]} listing the parameters (COMP_METADATA_TYPE_PARAMETER, 1)
  and the events (COMP_METADATA_TYPE_EVENTS, 4), served from PX4's ROMFS extras: etc/extras/parameters.json.xz and
  etc/extras/all_events.json.xz. Each CRC is MAVLink's CRC32 as PX4's generators compute it (the reflected table
  of 0xEDB88320, starting at 0, no final inversion: ftp_sandbox's crc32part) over the uncompressed JSON; each file
  is xz-compressed as PX4's build does with python's lzma, at preset 1 rather than PX4's 9 (the same container a
  client decompresses, about 10 % larger, made in milliseconds instead of a 0.6 s, 670 MB compression at start).
- parameters.json (PX4's Tools/px4params/jsonout.py layout: version, uid, scope, parameters [{name, type, default,
  group, shortDesc, units, min, max, volatile}]) lists the emulator's own parameter catalogue (every listed
  parameter with its type, default, stated range, unit and description), so it never disagrees with PARAM_VALUE.
  PX4's groups are not in the catalogue: a parameter's group is its name's prefix ("MPC" for MPC_XY_VEL_MAX).
- all_events.json is sitl_emu/events/metadata.py: exactly the events the emulator sends.
The files are written once per process into a private directory that the FTP root mounts read-only as etc/
(protocols/ftp.py), so a client downloads them over MAVLink FTP at the URIs above.
"""

from __future__ import annotations

import atexit
import json
import lzma
import shutil
import tempfile
import zlib
from functools import lru_cache
from pathlib import Path
from typing import Any

from sitl_emu.events.metadata import events_metadata
from sitl_emu.mavlink.wire.extra_messages import EXTRA
from sitl_emu.mavlink.wire.fastpack import Packed
from sitl_emu.params.catalog import px4_catalog
from sitl_emu.params.registry import FLT_MAX, ParamType

EXTRAS = "etc/extras"
GENERAL_FILE = "component_general.json.xz"
PARAMETERS_FILE = "parameters.json.xz"
EVENTS_FILE = "all_events.json.xz"
COMP_METADATA_TYPE_PARAMETER = 1
COMP_METADATA_TYPE_EVENTS = 4
MSG_COMPONENT_METADATA = 397
XZ_PRESET = 1


def uri(name: str) -> str:
    return f"mftp://{EXTRAS}/{name}"


def mavlink_crc32(data: bytes) -> int:
    """generate_crc.py's crc_update from 0 over the whole file (zlib's CRC-32 without its two inversions)."""
    return zlib.crc32(data, 0xFFFFFFFF) ^ 0xFFFFFFFF


def _dumps(doc: dict[str, Any]) -> bytes:
    return json.dumps(doc).encode()


def _xz(data: bytes) -> bytes:
    return lzma.compress(data, preset=XZ_PRESET)


def _bound(value: float) -> float | None:
    return value if abs(value) < FLT_MAX and abs(value) != float("inf") else None


def parameters_metadata() -> dict[str, Any]:
    catalog = px4_catalog()
    by_name = {d.name: d for d in catalog.defs}
    parameters = []
    for name in catalog.used:
        d = by_name[name]
        entry: dict[str, Any] = {"name": name, "type": "Int32" if d.type is ParamType.INT32 else "Float",
                                 "default": int(d.default) if d.type is ParamType.INT32 else d.default,
                                 "group": name.split("_", 1)[0], "shortDesc": d.doc}
        if d.unit:
            entry["units"] = d.unit
        for key, value in (("min", _bound(d.min)), ("max", _bound(d.max))):
            if value is not None and not (d.type is ParamType.INT32 and abs(value) >= 2**31 - 1):
                entry[key] = value
        if d.volatile:
            entry["volatile"] = True
        parameters.append(entry)
    return {"version": 1, "uid": 1, "scope": "Firmware", "parameters": parameters}


def general_metadata(crcs: dict[str, int]) -> dict[str, Any]:
    types = ((COMP_METADATA_TYPE_PARAMETER, PARAMETERS_FILE), (COMP_METADATA_TYPE_EVENTS, EVENTS_FILE))
    return {"version": 1, "metadataTypes": [{"type": t, "uri": uri(f), "fileCrc": crcs[f], "uriFallback": ""}
                                            for t, f in types]}


@lru_cache(maxsize=1)
def metadata_files() -> tuple[dict[str, bytes], dict[str, int]]:
    """(file name -> the xz bytes served, file name -> the CRC of its JSON)."""
    plain = {PARAMETERS_FILE: _dumps(parameters_metadata()), EVENTS_FILE: _dumps(events_metadata())}
    crcs = {name: mavlink_crc32(data) for name, data in plain.items()}
    plain[GENERAL_FILE] = _dumps(general_metadata(crcs))
    crcs[GENERAL_FILE] = mavlink_crc32(plain[GENERAL_FILE])
    return {name: _xz(data) for name, data in plain.items()}, crcs


@lru_cache(maxsize=1)
def etc_directory() -> Path:
    """A private directory holding extras/ with the three files (the FTP root's etc/), removed at exit."""
    top = Path(tempfile.mkdtemp(prefix="sitl_emu_etc_"))
    atexit.register(shutil.rmtree, top, True)
    extras = top / "etc" / "extras"
    extras.mkdir(parents=True)
    for name, data in metadata_files()[0].items():
        (extras / name).write_bytes(data)
    return top / "etc"


def component_metadata_message(time_boot_ms: int) -> Packed:
    return EXTRA.component_metadata_encode(time_boot_ms & 0xFFFFFFFF, metadata_files()[1][GENERAL_FILE],
                                           uri(GENERAL_FILE).encode())
