"""The ULog writer alone (bytes out), read back by pyulog; and a written log fetched over MAVLink FTP."""

from __future__ import annotations

import math
import struct

import pytest
from support.fakes import Harness
from support.ftp_client import FtpClient

from sitl_emu.log import ulog_writer as ulog
from sitl_emu.log.serving import attach_logger
from sitl_emu.mavlink.protocols.ftp import FtpProtocol
from sitl_emu.px4 import MavCmd
from sitl_emu.types import VehicleCommand
from sitl_emu.vehicle.vehicle import Vehicle

pyulog = pytest.importorskip("pyulog", reason="pyulog reads the logs back: pip install pyulog (the test extra)")
NAN = math.nan


def _file(tmp_path, *messages: bytes):
    path = tmp_path / "t.ulg"
    path.write_bytes(ulog.file_header(1000) + ulog.flag_bits() + b"".join(messages))
    return pyulog.ULog(str(path))


def test_a_written_file_reads_back_with_its_formats_infos_params_data_and_texts(tmp_path):
    fmt = ulog.MessageFormat("demo_topic", "uint64_t timestamp;float[3] xyz;bool ok;uint8_t[3] _padding0")
    assert fmt.text() == "demo_topic:uint64_t timestamp;float[3] xyz;bool ok;uint8_t[3] _padding0;"
    assert fmt.size == 8 + 12 + 1  # the trailing padding is not written (PX4: o_size_no_padding)
    defs, subs = ulog.formats_and_subscriptions([fmt])
    log = _file(tmp_path, ulog.info("sys_name", "PX4"), ulog.info("ver_sw_release", 0x010F04FF, "uint32_t"), defs,
                ulog.parameter("MPC_XY_VEL_MAX", 12.0, False), ulog.parameter("MAV_SYS_ID", 1, True),
                ulog.parameter_default("MPC_XY_VEL_MAX", 12.0, False), subs,
                ulog.DataPacker(fmt, 0, ("timestamp", "xyz", "ok"))((2000, 1.0, 2.0, 3.0, True)),
                ulog.DataPacker(fmt, 0, ("timestamp",))((3000,)), ulog.log_text(4, 2500, "warn me"), ulog.sync())
    assert not log.file_corruption
    assert log.msg_info_dict["sys_name"] == "PX4" and log.msg_info_dict["ver_sw_release"] == 0x010F04FF
    assert log.initial_parameters == {"MPC_XY_VEL_MAX": 12.0, "MAV_SYS_ID": 1}
    data = log.get_dataset("demo_topic").data
    assert list(data["timestamp"]) == [2000, 3000] and list(data["xyz[2]"]) == [3.0, 0.0]
    assert list(data["ok"]) == [1, 0]
    (text,) = log.logged_messages
    assert (text.log_level_str(), text.timestamp, text.message) == ("WARNING", 2500, "warn me")


def _data_message(msg_id: int, payload: bytes) -> bytes:
    """A 'D' message as the ULog format defines it: size (msg_id + payload), 'D', msg_id, payload."""
    return struct.pack("<HBH", 2 + len(payload), ord("D"), msg_id) + payload


def test_defaults_texts_and_bad_fields():
    fmt = ulog.MessageFormat("t", "uint64_t timestamp;float a;float b")
    fmt.set_defaults({"b": 7.0})
    assert ulog.DataPacker(fmt, 3, ("a",))((1.0,)) == _data_message(3, struct.pack("<Qff", 0, 1.0, 7.0))
    long_text = ulog.log_text(6, 0, "x" * 300)
    assert len(long_text) == 3 + 1 + 8 + ulog.MAX_TEXT  # PX4's 128-char message, NUL included
    with pytest.raises(ValueError):
        ulog.parse_fields("quaternion q")
    with pytest.raises(KeyError):
        fmt.set_defaults({"nope": 1})


def test_a_data_packer_writes_its_values_with_defaults_arrays_and_padding():
    fmt = ulog.MessageFormat("t", "uint64_t timestamp;float[3] xyz;float a;bool ok;uint8_t c;uint8_t[2] _padding0;"
                                  "float b;uint8_t[4] _padding1")
    fmt.set_defaults({"b": 7.0, "c": 3})
    pack = ulog.DataPacker(fmt, 5, ("timestamp", "xyz", "ok"))
    # every field in order, the middle padding as zero bytes, the trailing padding not written
    assert pack((2000, 1.0, 2.0, 3.0, True)) == _data_message(
        5, struct.pack("<Q3ff?B2xf", 2000, 1.0, 2.0, 3.0, 0.0, True, 3, 7.0))
    assert ulog.DataPacker(fmt, 1, ("b", "a"))((1.5, -2.0)) == _data_message(
        1, struct.pack("<Q3ff?B2xf", 0, 0.0, 0.0, 0.0, -2.0, False, 3, 1.5))
    with pytest.raises(ValueError):
        pack((2000, (1.0, 2.0, 3.0), True))  # an array goes in as its elements
    with pytest.raises(ValueError):
        ulog.DataPacker(fmt, 0, ("timestamp", "nope"))


def test_a_log_is_read_over_mavlink_ftp_when_the_log_directory_is_under_the_ftp_root(tmp_path):
    vehicle = Vehicle(seed=0)
    h = Harness(vehicle, handler_classes=[FtpProtocol.with_root(tmp_path)])
    logger = attach_logger(h.node, tmp_path / "log")  # PX4 SITL: FTP root = working directory, logs in log/
    try:
        h.run(3.0)
        vehicle.handle_command(VehicleCommand(MavCmd.COMPONENT_ARM_DISARM, (1.0, 0.0) + (NAN,) * 5))
        h.run(1.0)
        vehicle.handle_command(VehicleCommand(MavCmd.COMPONENT_ARM_DISARM, (0.0, 21196.0) + (NAN,) * 5))
        h.run(0.1)
        (path,) = logger.files
        assert not logger.writing
        ftp_path = "/" + path.relative_to(tmp_path).as_posix()  # "/log/YYYY-MM-DD/HH_MM_SS.ulg"
        assert FtpClient(h).read_file(ftp_path.encode()) == path.read_bytes()
    finally:
        h.close()
