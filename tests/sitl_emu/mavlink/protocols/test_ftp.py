"""MAVLink FTP as PX4's server answers it (src/modules/mavlink/mavlink_ftp.cpp), over loopback UDP in lockstep.

Round trips (list, read, write, CRC32, burst read, directories, rename, truncate), the single session, PX4's error
codes and its resend of the last reply. The path-escape suite is in test_ftp_escape.py.
"""

from __future__ import annotations

import errno
import os
from pathlib import Path

import pytest
from support.fakes import FakeVehicle, Harness
from support.ftp_client import FtpClient, request_payload

from sitl_emu.mavlink import version
from sitl_emu.mavlink.endpoint import load_handler_classes
from sitl_emu.mavlink.protocols.ftp import (
    BURST_CHUNK_BYTES,
    BURST_PACKETS_PER_TICK,
    MAX_DATA,
    SESSION_IDLE_US,
    Err,
    FtpProtocol,
    Op,
    Payload,
)

MAV_PROTOCOL_CAPABILITY_FTP = 32


@pytest.fixture()
def root(tmp_path: Path) -> Path:
    return tmp_path / "fs"


@pytest.fixture()
def ftp(root: Path):
    harness = Harness(FakeVehicle(), handler_classes=[FtpProtocol.with_root(root)])
    yield FtpClient(harness)
    harness.close()


def u32(data: bytes | bytearray) -> int:
    return int.from_bytes(data[:4], "little")


def test_autopilot_version_advertises_ftp_and_every_link_serves_it():
    assert version.CAPABILITIES & MAV_PROTOCOL_CAPABILITY_FTP
    assert FtpProtocol in load_handler_classes()


def test_root_is_created_on_the_first_request_and_listed_as_px4_does(ftp, root):
    assert not root.exists()
    assert ftp.list_dir(b"/") == [b"S", b"S"]  # "." and ".." are skip entries
    assert root.is_dir()
    (root / "b.bin").write_bytes(b"x" * 1234)
    (root / "a dir").mkdir()
    (root / "empty").write_bytes(b"")
    os.mkfifo(root / "pipe")
    os.symlink("b.bin", root / "link")
    assert ftp.list_dir(b"/") == [b"S", b"S", b"Da dir", b"Fb.bin\t1234", b"Fempty\t0", b"S", b"S"]
    assert ftp.list_dir(b"") == ftp.list_dir(b"/") == ftp.list_dir(b"./")


def test_listing_pages_by_offset_and_ends_with_eof(ftp, root):
    root.mkdir()
    names = [f"file_with_a_rather_long_name_{i:03d}.txt" for i in range(30)]
    for name in names:
        (root / name).write_bytes(b"12345")
    first = ftp.call(Op.LIST_DIRECTORY, b"/\0")
    assert first.opcode == Op.ACK and first.req_opcode == Op.LIST_DIRECTORY and 0 < first.size <= MAX_DATA
    assert bytes(first.data[first.size - 1:first.size]) == b"\0"
    assert ftp.list_dir(b"/") == [b"S", b"S"] + [f"F{n}\t5".encode() for n in names]
    assert ftp.nak(Op.LIST_DIRECTORY, b"/\0", offset=32) == (Err.EOF, 0)
    assert ftp.nak(Op.LIST_DIRECTORY, b"/\0", offset=1000) == (Err.EOF, 0)


def test_listing_a_missing_directory_or_a_file_is_file_not_found(ftp, root):
    root.mkdir()
    (root / "f").write_bytes(b"1")
    assert ftp.nak(Op.LIST_DIRECTORY, b"/nope\0") == (Err.FILE_NOT_FOUND, 0)
    assert ftp.nak(Op.LIST_DIRECTORY, b"/f\0") == (Err.FILE_NOT_FOUND, 0)


def test_read_round_trip_in_chunks_with_eof_and_the_size_at_open(ftp, root):
    root.mkdir()
    content = bytes(range(256)) * 7
    (root / "data.bin").write_bytes(content)
    assert ftp.read_file(b"/data.bin") == content
    opened = ftp.ok(Op.OPEN_FILE_RO, b"data.bin\0")
    assert (opened.session, opened.size, u32(opened.data)) == (0, 4, len(content))
    part = ftp.ok(Op.READ_FILE, offset=1000, size=100)
    assert bytes(part.data[:part.size]) == content[1000:1100] and part.offset == 1000
    assert ftp.nak(Op.READ_FILE, offset=len(content), size=10) == (Err.EOF, 0)
    ftp.ok(Op.TERMINATE_SESSION)
    assert ftp.nak(Op.READ_FILE, offset=0, size=10) == (Err.INVALID_SESSION, 0)


def test_write_round_trip_create_truncates_open_wo_does_not(ftp, root):
    content = os.urandom(3000)
    ftp.write_file(b"/up.bin", content)
    assert (root / "up.bin").read_bytes() == content
    ftp.ok(Op.OPEN_FILE_WO, b"up.bin\0")
    assert u32(ftp.ok(Op.WRITE_FILE, b"HEAD", offset=0).data) == 4
    ftp.ok(Op.TERMINATE_SESSION)
    assert (root / "up.bin").read_bytes() == b"HEAD" + content[4:]
    opened = ftp.ok(Op.CREATE_FILE, b"up.bin\0")
    assert u32(opened.data) == len(content)  # the size before truncation, as PX4 stats first
    ftp.ok(Op.TERMINATE_SESSION)
    assert (root / "up.bin").read_bytes() == b""


def test_crc32_is_px4s_crc32part(ftp, root):
    root.mkdir()
    (root / "bytes.bin").write_bytes(bytes(range(256)))
    (root / "ff.bin").write_bytes(b"\xff")
    (root / "empty.bin").write_bytes(b"")
    (root / "big.bin").write_bytes(bytes(range(256)) * 5 + b"tail")
    # MAVSDK's goldens (core/crc32_test.cpp): bytes 0..255 and a single 0xFF
    assert u32(ftp.ok(Op.CALC_FILE_CRC32, b"bytes.bin\0").data) == 0x2493092B
    assert u32(ftp.ok(Op.CALC_FILE_CRC32, b"ff.bin\0").data) == 0x2D02EF8D
    assert u32(ftp.ok(Op.CALC_FILE_CRC32, b"empty.bin\0").data) == 0
    assert u32(ftp.ok(Op.CALC_FILE_CRC32, b"big.bin\0").data) != u32(ftp.ok(Op.CALC_FILE_CRC32, b"bytes.bin\0").data)
    assert ftp.nak(Op.CALC_FILE_CRC32, b"missing.bin\0") == (Err.FILE_NOT_FOUND, 0)


def _burst(ftp: FtpClient, offset: int) -> list:
    seq = ftp.send(Op.BURST_READ_FILE, offset=offset, size=MAX_DATA)
    packets: list = []
    for _ in range(1000):
        packets += ftp.replies(ticks=1)
        if packets and (packets[-1].burst_complete or packets[-1].opcode == Op.NAK):
            break
    else:
        raise AssertionError("the burst never ended")
    assert [p.seq for p in packets] == [(seq + 1 + i) & 0xFFFF for i in range(len(packets))]
    return packets


def test_burst_read_streams_the_file_in_35k_bursts_then_eof(ftp, root):
    root.mkdir()
    content = os.urandom(100_000)
    (root / "log.ulg").write_bytes(content)
    ftp.ok(Op.OPEN_FILE_RO, b"log.ulg\0")
    out = bytearray()
    bursts = []
    while True:
        packets = _burst(ftp, len(out))
        bursts.append(packets)
        for p in packets:
            if p.opcode == Op.ACK:
                assert p.req_opcode == Op.BURST_READ_FILE and p.offset == len(out) and p.size <= MAX_DATA
                out += p.data[:p.size]
        if packets[-1].opcode == Op.NAK:
            assert packets[-1].data[0] == Err.EOF and packets[-1].req_opcode == Op.BURST_READ_FILE
            break
    assert bytes(out) == content
    first = bursts[0]
    assert first[-1].burst_complete == 1 and all(p.burst_complete == 0 for p in first[:-1])
    assert BURST_CHUNK_BYTES < sum(p.size for p in first) <= BURST_CHUNK_BYTES + BURST_PACKETS_PER_TICK * MAX_DATA
    assert len(first) % BURST_PACKETS_PER_TICK == 0  # a burst ends with the last packet of a tick
    ftp.ok(Op.TERMINATE_SESSION)


def test_burst_of_another_session_is_invalid_and_past_the_end_is_eof(ftp, root):
    root.mkdir()
    (root / "f").write_bytes(b"abc")
    assert ftp.nak(Op.BURST_READ_FILE, session=1) == (Err.INVALID_SESSION, 0)
    ftp.ok(Op.OPEN_FILE_RO, b"f\0")
    (eof,) = _burst(ftp, 3)
    assert eof.opcode == Op.NAK and eof.data[0] == Err.EOF


def test_directories_remove_rename_truncate(ftp, root):
    ftp.ok(Op.CREATE_DIRECTORY, b"/logs\0")
    assert (root / "logs").is_dir()
    assert ftp.nak(Op.CREATE_DIRECTORY, b"/logs\0") == (Err.FILE_EXISTS, 0)
    ftp.write_file(b"/logs/a.txt", b"0123456789")
    assert ftp.nak(Op.REMOVE_DIRECTORY, b"/logs\0") == (Err.FAIL_ERRNO, errno.ENOTEMPTY)
    ftp.ok(Op.TRUNCATE_FILE, b"/logs/a.txt\0", offset=4)
    assert (root / "logs" / "a.txt").read_bytes() == b"0123"
    ftp.ok(Op.RENAME, b"/logs/a.txt\0/b.txt\0")
    assert not (root / "logs" / "a.txt").exists() and (root / "b.txt").read_bytes() == b"0123"
    assert ftp.nak(Op.RENAME, b"/b.txt") == (Err.FAIL_ERRNO, errno.EINVAL)  # no second path
    assert ftp.nak(Op.RENAME, b"/b.txt\0") == (Err.FILE_PROTECTED, 0)  # an empty one: the root, never replaced
    assert ftp.nak(Op.REMOVE_FILE, b"/logs/a.txt\0") == (Err.FILE_NOT_FOUND, 0)
    assert ftp.nak(Op.REMOVE_FILE, b"/logs\0") == (Err.FAIL_ERRNO, errno.EISDIR)
    ftp.ok(Op.REMOVE_DIRECTORY, b"/logs\0")
    ftp.ok(Op.REMOVE_FILE, b"b.txt\0")
    assert list(root.iterdir()) == []


def test_one_session_per_link(ftp, root):
    root.mkdir()
    (root / "a").write_bytes(b"a")
    (root / "b").write_bytes(b"b")
    ftp.ok(Op.OPEN_FILE_RO, b"a\0")
    assert ftp.nak(Op.OPEN_FILE_RO, b"b\0") == (Err.NO_SESSIONS_AVAILABLE, 0)
    assert ftp.nak(Op.CREATE_FILE, b"c\0") == (Err.NO_SESSIONS_AVAILABLE, 0)
    assert not (root / "c").exists()
    assert ftp.nak(Op.READ_FILE, session=1, size=1) == (Err.INVALID_SESSION, 0)
    assert ftp.nak(Op.TERMINATE_SESSION, session=3) == (Err.INVALID_SESSION, 0)
    assert ftp.ok(Op.RESET_SESSIONS).size == 0
    ftp.ok(Op.OPEN_FILE_RO, b"b\0")
    assert ftp.ok(Op.READ_FILE, size=1).data[:1] == b"b"


def test_a_session_idle_for_10_s_is_closed(ftp, root):
    root.mkdir()
    (root / "a").write_bytes(b"a")
    ftp.ok(Op.OPEN_FILE_RO, b"a\0")
    ftp.h.run(SESSION_IDLE_US / 1e6 + 0.1)
    assert ftp.nak(Op.READ_FILE, size=1) == (Err.INVALID_SESSION, 0)
    ftp.ok(Op.OPEN_FILE_RO, b"a\0")


def test_write_without_a_session(ftp, root):
    assert ftp.nak(Op.WRITE_FILE, b"x", session=2) == (Err.INVALID_SESSION, 0)
    assert ftp.nak(Op.WRITE_FILE, b"x", session=0) == (Err.FAIL_ERRNO, errno.EBADF)  # PX4: lseek(-1) fails
    root.mkdir(exist_ok=True)
    (root / "ro").write_bytes(b"ro")
    ftp.ok(Op.OPEN_FILE_RO, b"ro\0")
    assert ftp.nak(Op.WRITE_FILE, b"x") == (Err.FAIL_ERRNO, errno.EBADF)
    assert (root / "ro").read_bytes() == b"ro"


@pytest.mark.parametrize("opcode", [16, 17, 127, 130, 255])
def test_unknown_opcodes(ftp, opcode):
    reply = ftp.call(opcode)
    assert (reply.opcode, reply.req_opcode, reply.size, reply.data[0]) == (Op.NAK, opcode, 1, Err.UNKNOWN_COMMAND)


def test_none_is_acked(ftp):
    reply = ftp.call(Op.NONE)
    assert (reply.opcode, reply.req_opcode) == (Op.ACK, Op.NONE)


def test_a_resent_request_gets_the_kept_reply_and_does_not_run_twice(ftp, root):
    seq = ftp.send(Op.CREATE_DIRECTORY, b"d\0", seq=41)
    (first,) = ftp.replies(until=seq + 1)
    assert first.opcode == Op.ACK and first.seq == 42
    (root / "d").rmdir()  # a second mkdir would succeed again: the resend must not run it
    ftp.send(Op.CREATE_DIRECTORY, b"d\0", seq=41)
    (again,) = ftp.replies(until=42)
    assert again.pack() == first.pack()
    assert not (root / "d").exists()
    assert ftp.call(Op.CREATE_DIRECTORY, b"d\0", seq=42).opcode == Op.ACK  # a new seq runs
    assert (root / "d").is_dir()


def test_large_replies_are_not_kept_so_a_resent_read_runs_again(ftp, root):
    root.mkdir()
    (root / "f").write_bytes(b"0123456789")
    ftp.ok(Op.OPEN_FILE_RO, b"f\0", seq=10)
    one = ftp.call(Op.READ_FILE, seq=11, offset=0, size=8)
    two = ftp.call(Op.READ_FILE, seq=11, offset=2, size=8)  # same seq, but the 8-byte reply was not kept
    assert bytes(one.data[:one.size]) == b"01234567" and bytes(two.data[:two.size]) == b"23456789"


@pytest.mark.parametrize("seq", [0, 1, 1000, 0xFFFE, 0xFFFF])
def test_any_sequence_number_is_served_and_the_reply_is_seq_plus_one(ftp, seq):
    reply = ftp.call(Op.LIST_DIRECTORY, b"/\0", seq=seq)
    assert reply.opcode == Op.ACK and reply.seq == (seq + 1) & 0xFFFF


def test_requests_for_another_system_or_component_are_ignored(ftp, root):
    other = FtpClient(ftp.h, target=(2, 1))
    other.send(Op.CREATE_DIRECTORY, b"x\0")
    wrong_comp = FtpClient(ftp.h, target=(1, 42))
    wrong_comp.send(Op.CREATE_DIRECTORY, b"y\0")
    assert ftp.replies(ticks=5) == []
    assert not (root / "x").exists() and not (root / "y").exists()
    broadcast = FtpClient(ftp.h, target=(0, 0))
    assert broadcast.call(Op.CREATE_DIRECTORY, b"z\0").opcode == Op.ACK


def test_default_root_is_fs_in_the_working_directory(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    harness = Harness(FakeVehicle(), handler_classes=[FtpProtocol])
    try:
        FtpClient(harness).write_file(b"/hello.txt", b"hi")
    finally:
        harness.close()
    assert (tmp_path / "fs" / "hello.txt").read_bytes() == b"hi"


def test_a_sim_vehicle_serves_ftp_and_the_empty_log_list_on_both_links(tmp_path, monkeypatch):
    """The default handler list of a real node (sitl_emu.testing.Sim), reached with pymavlink's own connection."""
    from pymavlink import mavutil

    from sitl_emu.testing import Sim

    monkeypatch.setattr(FtpProtocol, "root", tmp_path / "fs")
    (tmp_path / "fs").mkdir()
    (tmp_path / "fs" / "params.txt").write_bytes(b"MPC_XY_CRUISE 5\n")
    with Sim() as sim:
        for host, port in (sim.ports(0).api, sim.ports(0).gcs):
            conn = mavutil.mavlink_connection(f"udpout:{host}:{port}", source_system=255, source_component=190)
            try:
                conn.mav.file_transfer_protocol_send(0, 1, 1, request_payload(Op.LIST_DIRECTORY, b"/\0", seq=7))
                conn.mav.log_request_list_send(1, 1, 0, 0xFFFF)
                sim.run_for(0.05)
                got = {}
                while (msg := conn.recv_match(type=["FILE_TRANSFER_PROTOCOL", "LOG_ENTRY"], blocking=False)):
                    got[msg.get_type()] = msg
            finally:
                conn.close()
            reply = Payload.unpack(bytes(got["FILE_TRANSFER_PROTOCOL"].payload))
            assert (reply.seq, reply.opcode) == (8, Op.ACK)
            assert bytes(reply.data[:reply.size]) == b"S\0S\0Detc\0Fparams.txt\t16\0"  # etc/: PX4 SITL's ROMFS extras
            entry = got["LOG_ENTRY"]
            assert (entry.id, entry.num_logs, entry.last_log_num, entry.time_utc, entry.size) == (0, 0, 0, 0, 0)
