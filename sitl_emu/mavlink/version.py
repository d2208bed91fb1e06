"""AUTOPILOT_VERSION and PROTOCOL_VERSION as PX4 v1.15 SITL sends them.

Sources: mavlink_main.cpp send_autopilot_capabilities (~l.1263) and send_protocol_version (~l.1348); reference 9c.2,
11.5. pymavlink's dialects lack PROTOCOL_VERSION (#300), so its message class is defined here from common.xml: fastpack
builds the message from that metadata as from pymavlink's own classes, and test clients parse it with the class.
"""

from __future__ import annotations

import struct
from typing import TYPE_CHECKING

from pymavlink.dialects.v20 import development as dialect

from sitl_emu.mavlink.wire.fastpack import spec_for_class

if TYPE_CHECKING:
    from pymavlink.dialects.v20.development import MAVLink

    from sitl_emu.mavlink.wire.encoding import MessageEncoder
    from sitl_emu.mavlink.wire.fastpack import Packed

# MAV_PROTOCOL_CAPABILITY: MISSION_FLOAT|PARAM_FLOAT|MISSION_INT|COMMAND_INT|PARAM_ENCODE_BYTEWISE|FTP|
# SET_ATTITUDE_TARGET|SET_POSITION_TARGET_LOCAL_NED|FLIGHT_TERMINATION|MAVLINK2|MISSION_FENCE|MISSION_RALLY
CAPABILITIES = 59647
FIRMWARE_VERSION = (1, 15, 4)
FIRMWARE_TYPE_OFFICIAL = 255  # FIRMWARE_VERSION_TYPE_OFFICIAL
GIT_HASH = bytes.fromhex("6f2a5c7e1d3b9a80")  # an emulator, not a real PX4 build: a fixed stand-in hash
UID_BASE = 0x5349544C454D5500  # "SITLEMU\0"; PX4 SITL adds sysid-1 to its uid


def sw_version(major: int, minor: int, patch: int, fw_type: int = FIRMWARE_TYPE_OFFICIAL) -> int:
    """(major<<24)|(minor<<16)|(patch<<8)|type, e.g. v1.15.4 -> 0x010F04FF."""
    return (major << 24) | (minor << 16) | (patch << 8) | fw_type


FLIGHT_SW_VERSION = sw_version(*FIRMWARE_VERSION)


def autopilot_version(encoder: MessageEncoder, sysid: int) -> Packed:
    custom = list(GIT_HASH)
    return encoder.autopilot_version_encode(
        CAPABILITIES, FLIGHT_SW_VERSION, FLIGHT_SW_VERSION, 0, 0, custom, custom, [0] * 8, 0, 0,
        UID_BASE + sysid - 1, [0] * 18)


class ProtocolVersionMessage(dialect.MAVLink_message):
    """PROTOCOL_VERSION (#300): version, min_version, max_version, spec/library hashes (common.xml)."""

    # pymavlink's MAVLink_message declares these as (instance-typed) class attributes, as its generated classes set
    # them; ClassVar here would be an override mypy refuses.
    id = 300
    msgname = "PROTOCOL_VERSION"
    fieldnames = ["version", "min_version", "max_version", "spec_version_hash", "library_version_hash"]  # noqa: RUF012
    ordered_fieldnames = fieldnames
    fieldtypes = ["uint16_t", "uint16_t", "uint16_t", "uint8_t", "uint8_t"]  # noqa: RUF012
    fielddisplays_by_name: dict[str, str] = {}  # noqa: RUF012
    fieldenums_by_name: dict[str, str] = {}  # noqa: RUF012
    fieldunits_by_name: dict[str, str] = {}  # noqa: RUF012
    native_format = bytearray(b"<HHHBB")
    orders = [0, 1, 2, 3, 4]  # noqa: RUF012
    lengths = [1, 1, 1, 8, 8]  # noqa: RUF012
    array_lengths = [0, 0, 0, 8, 8]  # noqa: RUF012
    crc_extra = 217
    unpacker = struct.Struct("<HHH8B8B")
    instance_field = None
    instance_offset = -1

    def __init__(self, version: int, min_version: int, max_version: int, spec_version_hash: list[int],
                 library_version_hash: list[int]) -> None:
        dialect.MAVLink_message.__init__(self, self.id, self.msgname)
        self._fieldnames = self.fieldnames
        self._instance_field = None
        self._instance_offset = -1
        self.version = version
        self.min_version = min_version
        self.max_version = max_version
        self.spec_version_hash = spec_version_hash
        self.library_version_hash = library_version_hash

    def pack(self, mav: MAVLink, force_mavlink1: bool = False) -> bytes:
        payload = self.unpacker.pack(self.version, self.min_version, self.max_version, *self.spec_version_hash,
                                     *self.library_version_hash)
        return self._pack(mav, self.crc_extra, payload, force_mavlink1=force_mavlink1)


def protocol_version() -> Packed:
    """PX4: {version 200, min_version 100, max_version 203} (MAVLink 2.0, supports 1.0-2.03)."""
    return _PROTOCOL_VERSION.encode(200, 100, 203, [0] * 8, list(GIT_HASH))


_PROTOCOL_VERSION = spec_for_class(ProtocolVersionMessage)
