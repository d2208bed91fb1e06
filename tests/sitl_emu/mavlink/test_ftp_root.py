"""The FTP root looks like PX4 SITL's working directory: log/ (the flight logs) and the parameter file beside what
clients put there, read-only, and nothing outside any of them reachable.

PX4 SITL's MavlinkFTP serves its working directory (mavlink_ftp.cpp `_root_dir`), where the logger writes log/
(LOG_ROOT = PX4_STORAGEDIR "/log") and the parameters are kept; QGroundControl's and MAVSDK's FTP browsers list
"/" and "/log" there.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from support.fakes import FakeVehicle, Harness
from support.ftp_client import FtpClient

from sitl_emu.log.serving import handler_classes
from sitl_emu.mavlink.protocols.ftp import Err, FtpProtocol, Op


@pytest.fixture()
def world(tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    """`serve`'s layout in tmp_path: fs/ (the writable root), log/2026-01-02/ with one log, parameters.params."""
    monkeypatch.chdir(tmp_path)
    logs = tmp_path / "log" / "2026-01-02"
    logs.mkdir(parents=True)
    (logs / "10_00_00.ulg").write_bytes(b"ULog" + bytes(600))
    (tmp_path / "parameters.params").write_text("1 1 MPC_XY_VEL_MAX 9 9\n")
    (tmp_path / "secret.txt").write_bytes(b"outside")
    classes = [c for c in handler_classes(tmp_path / "log", tmp_path / "parameters.params") if c.__name__ ==
               FtpProtocol.__name__]
    harness = Harness(FakeVehicle(), handler_classes=classes)
    yield FtpClient(harness), tmp_path
    harness.close()


def test_root_lists_etc_log_and_the_parameter_file_beside_the_clients_files(world):
    ftp, tmp = world
    assert ftp.list_dir(b"/") == [b"S", b"S", b"Detc", b"Dlog", b"Fparameters.params\t23"]
    ftp.write_file(b"/mine.txt", b"hello")
    assert (tmp / "fs" / "mine.txt").read_bytes() == b"hello"
    assert ftp.list_dir(b"/") == [b"S", b"S", b"Detc", b"Dlog", b"Fmine.txt\t5", b"Fparameters.params\t23"]


def test_logs_are_listed_and_downloaded_under_log(world):
    ftp, _tmp = world
    assert ftp.list_dir(b"/log") == [b"S", b"S", b"D2026-01-02"]
    assert ftp.list_dir(b"/log/2026-01-02") == [b"S", b"S", b"F10_00_00.ulg\t604"]
    assert ftp.read_file(b"/log/2026-01-02/10_00_00.ulg") == b"ULog" + bytes(600)
    assert ftp.read_file(b"/parameters.params") == b"1 1 MPC_XY_VEL_MAX 9 9\n"


def test_etc_extras_holds_the_component_metadata(world):
    ftp, _tmp = world
    assert ftp.list_dir(b"/etc") == [b"S", b"S", b"Dextras"]
    names = sorted(e.split(b"\t")[0] for e in ftp.list_dir(b"/etc/extras") if e != b"S")
    assert names == [b"Fall_events.json.xz", b"Fcomponent_general.json.xz", b"Fparameters.json.xz"]
    assert ftp.nak(Op.REMOVE_FILE, b"/etc/extras/parameters.json.xz\0") == (Err.FILE_PROTECTED, 0)


def test_mounts_are_read_only(world):
    ftp, tmp = world
    log = b"/log/2026-01-02/10_00_00.ulg\0"
    for op, data in ((Op.REMOVE_FILE, log), (Op.OPEN_FILE_WO, log), (Op.CREATE_FILE, b"/log/new.ulg\0"),
                     (Op.TRUNCATE_FILE, log), (Op.CREATE_DIRECTORY, b"/log/d\0"), (Op.REMOVE_DIRECTORY, b"/log\0"),
                     (Op.RENAME, log + b"/stolen.ulg\0"), (Op.RENAME, b"/x\0/log\0"),
                     (Op.REMOVE_FILE, b"/parameters.params\0")):
        assert ftp.nak(op, data) == (Err.FILE_PROTECTED, 0), (op, data)
    assert (tmp / "log" / "2026-01-02" / "10_00_00.ulg").stat().st_size == 604
    assert (tmp / "parameters.params").exists() and not (tmp / "fs" / "stolen.ulg").exists()


def test_nothing_outside_a_mount_is_reachable_through_it(world):
    ftp, tmp = world
    os.symlink(tmp / "secret.txt", tmp / "log" / "escape")
    assert ftp.nak(Op.OPEN_FILE_RO, b"/log/escape\0") == (Err.FILE_PROTECTED, 0)
    assert ftp.nak(Op.OPEN_FILE_RO, b"/log/../secret.txt\0") == (Err.FILE_PROTECTED, 0)
    assert ftp.nak(Op.OPEN_FILE_RO, b"/parameters.params/x\0")[0] in (Err.FILE_PROTECTED, Err.FAIL_ERRNO,
                                                                        Err.FILE_NOT_FOUND)


def test_a_mount_that_does_not_exist_yet_is_not_listed(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    classes = [c for c in handler_classes(tmp_path / "log", tmp_path / "parameters.params")
               if c.__name__ == FtpProtocol.__name__]
    harness = Harness(FakeVehicle(), handler_classes=classes)
    try:
        assert FtpClient(harness).list_dir(b"/") == [b"S", b"S", b"Detc"]  # the metadata is always there
    finally:
        harness.close()
