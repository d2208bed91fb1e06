"""What a log says about the system before its data: the version infos and the parameters.

Source: PX4 src/modules/logger/logger.cpp write_version (the 'I' messages: ver_sw, ver_sw_release, ver_hw,
sys_name "PX4", sys_os_name, sys_os_ver_release, ver_data_format 2, sys_uuid, time_ref_utc, boot_time_utc_us),
write_parameters ('P': every used parameter, "int32_t NAME" or "float NAME") and write_parameter_defaults ('Q':
for a parameter whose value differs from its default, the default, marked system and current setup as PX4 does when
the airframe leaves the system default alone). ver_sw is PX4's git hash: the emulator's stand-in hash of
AUTOPILOT_VERSION (mavlink/version.py), so a log and the link tell the same version.
"""

from __future__ import annotations

from sitl_emu.log import ulog_writer as ulog
from sitl_emu.mavlink.version import FLIGHT_SW_VERSION, GIT_HASH, UID_BASE
from sitl_emu.params import ParamRegistry, ParamType

VER_HW = "PX4_SITL"  # px4_board_name() of the SITL build
OS_NAME = "Linux"
DATA_FORMAT = 2  # logger.cpp: ver_data_format
SDLOG_UTC_OFFSET_MIN = 0


def version_infos(sysid: int, boot_time_utc_us: int) -> bytes:
    uid = UID_BASE + sysid - 1  # AUTOPILOT_VERSION.uid of this vehicle
    return b"".join((
        ulog.info("ver_sw", GIT_HASH.hex()),
        ulog.info("ver_sw_release", FLIGHT_SW_VERSION, "uint32_t"),
        ulog.info("ver_hw", VER_HW),
        ulog.info("sys_name", "PX4"),
        ulog.info("sys_os_name", OS_NAME),
        ulog.info("ver_data_format", DATA_FORMAT, "uint32_t"),
        ulog.info("sys_uuid", f"{uid:024X}"),
        ulog.info("time_ref_utc", SDLOG_UTC_OFFSET_MIN * 60, "int32_t"),
        ulog.info("boot_time_utc_us", boot_time_utc_us, "uint64_t"),
    ))


def parameter_messages(params: ParamRegistry) -> bytes:
    """'P' for every used parameter, then 'Q' with the default of those that differ from it."""
    values, defaults = [], []
    for d in params:
        is_int = d.type is ParamType.INT32
        value = params.get(d.name)
        values.append(ulog.parameter(d.name, value, is_int))
        if not params.is_default(d.name):
            kinds = ulog.DEFAULT_SYSTEM | ulog.DEFAULT_CURRENT_SETUP
            defaults.append(ulog.parameter_default(d.name, d.default, is_int, kinds))
    return b"".join(values + defaults)
