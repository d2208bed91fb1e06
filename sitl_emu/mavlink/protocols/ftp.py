"""MAVLink FTP (FILE_TRANSFER_PROTOCOL, #110) as PX4's server answers it, over a sandboxed root directory.

Source: PX4 src/modules/mavlink/mavlink_ftp.cpp and mavlink_ftp.h (v1.15-v1.17); what a client expects: MAVSDK
core/mavlink_ftp_client.cpp. In short:
- The 251-byte payload: seq u16, session u8, opcode u8, size u8, req_opcode u8, burst_complete u8, a padding byte,
  offset u32 (little endian), then 239 bytes of data.
- A request with size > 239 is answered NAK InvalidDataSize. A request whose seq is one below the seq of the last
  reply PX4 kept (it keeps replies of at most 4 data bytes: acks, naks, open, write and CRC results) is a resend:
  that reply goes out again and the command does not run twice. Any other seq is served.
- The reply is the request with seq + 1, opcode ACK (128) or NAK (129) and req_opcode the command. A NAK carries
  its error code in data[0] (size 1) and, for FailErrno, the errno in data[1] (size 2); errno EEXIST is reported
  as FileExists and ENOENT as FileNotFound.
- One session (0) per link: a second open gets NoSessionsAvailable; read or terminate of another session, or of
  none, gets InvalidSession. A session left 10 s without a request is closed.
- ListDirectory: the entries from index `offset` as PX4 packs them (ftp_sandbox.py); nothing left past offset 0
  is EOF. ReadFile reads `size` bytes at `offset`, EOF at or past the size the file had when it was opened.
- BurstReadFile is not acked: from the next tick the file streams in ACK packets of up to 239 bytes, seq counting
  on from the request's + 1, BURST_PACKETS_PER_TICK per tick; once more than 35000 bytes went out, the last packet
  of a tick has burst_complete 1 and the burst ends (the client asks for the next); at the end of the file a NAK EOF
  ends it. CalcFileCRC32 answers PX4's crc32part in 4 bytes.
Where we differ on purpose: no path ever leaves the root (ftp_sandbox.py; a refused path is NAK FileProtected, the
code PX4 gives a write outside its storage); a failed request reports its own errno (PX4 may report one left by an
earlier request); a burst that finds the file shorter than when it was opened ends with EOF (PX4 would keep
sending empty packets).

The root: FtpProtocol.root, or `fs/` in the working directory the emulator started in (created on the first
request), as PX4 SITL serves its working directory; FtpProtocol.mounts add PX4 SITL's read-only log/ and parameter
file to it (ftp_sandbox.py), and etc/ holds the component metadata (component_metadata.py) unless with_root() was
given a root of its own. `FtpProtocol.with_root(path, mounts)` is the class to list for a node.
"""

from __future__ import annotations

import errno
import io
import os
import struct
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from enum import IntEnum
from typing import TYPE_CHECKING, ClassVar, cast

from sitl_emu.mavlink.protocols.component_metadata import etc_directory
from sitl_emu.mavlink.protocols.ftp_sandbox import PathRefused, Sandbox, c_string, crc32_file, listing

if TYPE_CHECKING:
    from pymavlink.dialects.v20.development import MAVLink_file_transfer_protocol_message, MAVLink_message

    from sitl_emu.mavlink.context import LinkContext
    from sitl_emu.mavlink.wire.fastpack import Packed

PAYLOAD_LEN = 251
MAX_DATA = 239  # PAYLOAD_LEN - the 12-byte header (kMaxDataLength)
KEPT_REPLY_MAX_SIZE = 4  # replies PX4 keeps for a resent request
SESSION_IDLE_US = 10_000_000
BURST_CHUNK_BYTES = 35_000  # "perform transfers in 35K chunks"
# PX4 fills its 1500-byte UDP budget each 1.5 ms loop pass (5 packets); per 4 ms tick that is about 12
BURST_PACKETS_PER_TICK = 12
_HEADER, _U32 = struct.Struct("<HBBBBBBI"), struct.Struct("<I")


class Op(IntEnum):
    NONE = 0
    TERMINATE_SESSION = 1
    RESET_SESSIONS = 2
    LIST_DIRECTORY = 3
    OPEN_FILE_RO = 4
    READ_FILE = 5
    CREATE_FILE = 6
    WRITE_FILE = 7
    REMOVE_FILE = 8
    CREATE_DIRECTORY = 9
    REMOVE_DIRECTORY = 10
    OPEN_FILE_WO = 11
    TRUNCATE_FILE = 12
    RENAME = 13
    CALC_FILE_CRC32 = 14
    BURST_READ_FILE = 15
    ACK = 128
    NAK = 129


class Err(IntEnum):
    NONE = 0
    FAIL = 1
    FAIL_ERRNO = 2
    INVALID_DATA_SIZE = 3
    INVALID_SESSION = 4
    NO_SESSIONS_AVAILABLE = 5
    EOF = 6
    UNKNOWN_COMMAND = 7
    FILE_EXISTS = 8
    FILE_PROTECTED = 9
    FILE_NOT_FOUND = 10


class FtpNak(Exception):
    def __init__(self, code: Err, err_no: int = 0) -> None:
        super().__init__(code.name)
        self.code, self.err_no = code, err_no


def nak_for(err: OSError) -> FtpNak:
    """PX4's errno mapping for a failed request."""
    code = err.errno or errno.EIO
    if code == errno.EEXIST:
        return FtpNak(Err.FILE_EXISTS)
    if code == errno.ENOENT:
        return FtpNak(Err.FILE_NOT_FOUND)
    return FtpNak(Err.FAIL_ERRNO, code)


@dataclass(slots=True)
class Payload:
    seq: int
    session: int
    opcode: int
    size: int
    req_opcode: int
    burst_complete: int
    padding: int
    offset: int
    data: bytearray

    @classmethod
    def unpack(cls, raw: bytes) -> Payload:
        raw = raw[:PAYLOAD_LEN].ljust(PAYLOAD_LEN, b"\0")
        seq, session, opcode, size, req_opcode, burst_complete, padding, offset = _HEADER.unpack_from(raw)
        return cls(seq, session, opcode, size, req_opcode, burst_complete, padding, offset,
                   bytearray(raw[_HEADER.size:]))

    @classmethod
    def stream_packet(cls, seq: int, offset: int) -> Payload:
        return cls(seq, 0, Op.ACK, 0, Op.BURST_READ_FILE, 0, 0, offset, bytearray(MAX_DATA))

    def pack(self) -> bytes:
        return _HEADER.pack(self.seq, self.session, self.opcode, self.size, self.req_opcode, self.burst_complete,
                            self.padding, self.offset) + bytes(self.data)

    def path(self) -> bytes:
        """The data as PX4's _data_as_cstring reads it: ended at data[size] (at most data[238]) or an earlier NUL."""
        return c_string(bytes(self.data[:min(self.size, MAX_DATA - 1)]))

    def second_path(self, first: bytes) -> bytes:
        """Rename's new path: the C string after the first one's NUL."""
        return c_string(bytes(self.data[len(first) + 1:min(self.size, MAX_DATA - 1)]))

    def set_data(self, data: bytes) -> None:
        self.data[:len(data)] = data
        self.size = len(data)

    def fail(self, nak: FtpNak) -> None:
        self.opcode = Op.NAK
        self.data[0] = nak.code
        self.size = 1
        if nak.code == Err.FAIL_ERRNO:
            self.data[1] = nak.err_no & 0xFF
            self.size = 2


@dataclass(slots=True)
class _Burst:
    offset: int
    seq: int
    target: tuple[int, int]
    sent_bytes: int = 0


class FtpProtocol:
    """One instance per link, as PX4 runs one MavlinkFTP per mavlink instance: one session each."""

    MESSAGES: ClassVar[tuple[str, ...]] = ("FILE_TRANSFER_PROTOCOL",)
    root: ClassVar[str | os.PathLike[str] | None] = None  # None: ./fs of the working directory
    mounts: ClassVar[Mapping[str, str | os.PathLike[str]]] = {}  # read-only top-level names (ftp_sandbox.py)
    metadata: ClassVar[bool] = True  # etc/: PX4's ROMFS extras, the component metadata

    @classmethod
    def with_root(cls, root: str | os.PathLike[str] | None, mounts: Mapping[str, str | os.PathLike[str]] | None = None,
                  metadata: bool = False) -> type[FtpProtocol]:
        """This protocol serving `root` with `mounts` (and etc/ if `metadata`): a class for a node's handler list."""
        attrs = {"root": root, "mounts": dict(mounts or {}), "metadata": metadata}
        return cast("type[FtpProtocol]", type(cls.__name__, (cls,), attrs))

    def __init__(self) -> None:
        root = self.root if self.root is not None else os.path.join(os.getcwd(), "fs")
        etc = {"etc": etc_directory()} if self.metadata else {}
        self.sandbox = Sandbox(root, {**etc, **self.mounts})
        self._file: io.FileIO | None = None
        self._file_size = 0  # of the file last opened (PX4 keeps it after the session ends)
        self._burst: _Burst | None = None
        self._kept_reply: Packed | None = None
        self._kept_seq = -1
        self._last_request_us = 0
        self._source = (0, 0)
        self._work: dict[int, Callable[[Payload], None]] = {
            Op.NONE: lambda p: None, Op.TERMINATE_SESSION: self._terminate, Op.RESET_SESSIONS: self._reset,
            Op.LIST_DIRECTORY: self._list, Op.OPEN_FILE_RO: self._open_ro, Op.READ_FILE: self._read,
            Op.CREATE_FILE: self._create, Op.WRITE_FILE: self._write, Op.REMOVE_FILE: self._remove_file,
            Op.CREATE_DIRECTORY: self._mkdir, Op.REMOVE_DIRECTORY: self._rmdir, Op.OPEN_FILE_WO: self._open_wo,
            Op.TRUNCATE_FILE: self._truncate, Op.RENAME: self._rename, Op.CALC_FILE_CRC32: self._crc32,
            Op.BURST_READ_FILE: self._start_burst,
        }

    # --- requests ----------------------------------------------------------------------------------------------
    def handle(self, msg: MAVLink_message, ctx: LinkContext) -> None:
        ftp = cast("MAVLink_file_transfer_protocol_message", msg)  # MESSAGES: the endpoint sends only these
        if ftp.target_system not in (0, ctx.sysid) or ftp.target_component not in (0, ctx.compid):
            return
        self._last_request_us = ctx.now_us
        self._source = (msg.get_srcSystem(), msg.get_srcComponent())
        p = Payload.unpack(bytes(ftp.payload))
        if p.size <= MAX_DATA and self._kept_reply is not None and p.seq + 1 == self._kept_seq:
            ctx.send(self._kept_reply)  # the reply got lost and the client asks again
            return
        self._execute(p)
        p.seq = (p.seq + 1) & 0xFFFF
        self._kept_reply = None
        if not (p.opcode == Op.ACK and p.req_opcode == Op.BURST_READ_FILE):  # a burst answers with its packets
            self._reply(p, self._source, ctx)

    def _execute(self, p: Payload) -> None:
        p.req_opcode = p.opcode
        p.opcode = Op.ACK
        try:
            if p.size > MAX_DATA:
                raise FtpNak(Err.INVALID_DATA_SIZE)
            work = self._work.get(p.req_opcode)
            if work is None:
                raise FtpNak(Err.UNKNOWN_COMMAND)
            try:
                work(p)
            except PathRefused as err:
                raise FtpNak(Err.FILE_PROTECTED) from err
            except OSError as err:
                raise nak_for(err) from err
        except FtpNak as nak:
            p.fail(nak)

    def _reply(self, p: Payload, target: tuple[int, int], ctx: LinkContext) -> None:
        msg = ctx.encoder.file_transfer_protocol_encode(0, target[0], target[1], p.pack())
        if p.size <= KEPT_REPLY_MAX_SIZE:
            self._kept_reply, self._kept_seq = msg, p.seq
        ctx.send(msg)

    # --- sessions ----------------------------------------------------------------------------------------------
    def _require_session(self, p: Payload) -> io.FileIO:
        if p.session != 0 or self._file is None:
            raise FtpNak(Err.INVALID_SESSION)
        return self._file

    def _close(self) -> None:
        if self._file is not None:
            self._file.close()
            self._file = None
        self._burst = None

    def _terminate(self, p: Payload) -> None:
        self._require_session(p)
        self._close()
        p.size = 0

    def _reset(self, p: Payload) -> None:
        self._close()
        p.size = 0

    def _open(self, p: Payload, flags: int) -> None:
        if self._file is not None:
            raise FtpNak(Err.NO_SESSIONS_AVAILABLE)
        path = self.sandbox.target(p.path(), write=flags != os.O_RDONLY)
        try:
            size = os.stat(path).st_size
        except OSError:
            size = 0  # PX4 goes on to open(), which fails for a missing file opened for reading
        fd = os.open(path, flags | os.O_NOFOLLOW | os.O_CLOEXEC, 0o666)
        self._file = io.FileIO(fd, "r+")  # the mode only lets both calls through: the descriptor's flags rule
        self._file_size = size
        p.session = 0
        p.set_data(_U32.pack(size & 0xFFFFFFFF))

    def _open_ro(self, p: Payload) -> None:
        self._open(p, os.O_RDONLY)

    def _create(self, p: Payload) -> None:
        self._open(p, os.O_CREAT | os.O_TRUNC | os.O_WRONLY)

    def _open_wo(self, p: Payload) -> None:
        self._open(p, os.O_CREAT | os.O_WRONLY)

    def _read_at(self, offset: int, count: int) -> bytes:
        if self._file is None:  # a burst may run without a session, as in PX4: read() on fd -1
            raise OSError(errno.EBADF, "no open file")
        self._file.seek(offset)
        return self._file.read(count) or b""

    def _read(self, p: Payload) -> None:
        self._require_session(p)
        if p.offset >= self._file_size:
            raise FtpNak(Err.EOF)
        p.set_data(self._read_at(p.offset, p.size))

    def _write(self, p: Payload) -> None:
        if p.session != 0 and self._file is None:  # PX4 checks with && here: session 0 goes on to fail in lseek
            raise FtpNak(Err.INVALID_SESSION)
        if self._file is None:
            raise OSError(errno.EBADF, "no open file")
        self._file.seek(p.offset)
        written = self._file.write(bytes(p.data[:p.size])) or 0
        p.set_data(_U32.pack(written))

    # --- paths ---------------------------------------------------------------------------------------------------
    def _list(self, p: Payload) -> None:
        path = self.sandbox.target(p.path())
        mounted = self.sandbox.mount_entries() if self.sandbox.is_root(path) else None
        try:
            data, ended = listing(path, p.offset, MAX_DATA, mounted)
        except OSError as err:
            raise FtpNak(Err.FILE_NOT_FOUND) from err  # PX4: opendir() failed
        if not data and ended and p.offset != 0:
            raise FtpNak(Err.EOF)
        p.set_data(data)

    def _changeable_entry(self, raw: bytes) -> bytes:
        path = self.sandbox.entry(raw)
        if path == self.sandbox.root:
            raise PathRefused("the root itself")
        return path

    def _remove_file(self, p: Payload) -> None:
        os.unlink(self._changeable_entry(p.path()))
        p.size = 0

    def _mkdir(self, p: Payload) -> None:
        os.mkdir(self.sandbox.entry(p.path()), 0o777)
        p.size = 0

    def _rmdir(self, p: Payload) -> None:
        os.rmdir(self._changeable_entry(p.path()))
        p.size = 0

    def _truncate(self, p: Payload) -> None:
        path = self.sandbox.target(p.path(), write=True)
        p.size = 0
        os.truncate(path, p.offset)

    def _rename(self, p: Payload) -> None:
        old = p.path()
        if len(old) == p.size:  # no second path
            raise OSError(errno.EINVAL, "rename needs two paths")
        new = p.second_path(old)
        os.rename(self._changeable_entry(old), self._changeable_entry(new))
        p.size = 0

    def _crc32(self, p: Payload) -> None:
        p.set_data(_U32.pack(crc32_file(self.sandbox.target(p.path()))))

    # --- burst -------------------------------------------------------------------------------------------------
    def _start_burst(self, p: Payload) -> None:
        if p.session != 0 and self._file is None:  # && as in PX4: session 0 streams even without a file
            raise FtpNak(Err.INVALID_SESSION)
        self._burst = _Burst(p.offset, (p.seq + 1) & 0xFFFF, self._source)

    def tick(self, ctx: LinkContext) -> bool:
        """The idle session's timeout and the burst; False when neither is under way (idle until a request)."""
        if self._file is not None and ctx.now_us - self._last_request_us > SESSION_IDLE_US:
            self._close()  # "Session was closed without activity"
            self._kept_reply = None
        if self._burst is not None:
            self._stream(self._burst, ctx)
        return self._file is not None or self._burst is not None

    def _stream(self, burst: _Burst, ctx: LinkContext) -> None:
        for n in range(1, BURST_PACKETS_PER_TICK + 1):
            p = Payload.stream_packet(burst.seq, burst.offset)
            burst.seq = (burst.seq + 1) & 0xFFFF
            done = self._fill_burst_packet(p, burst)
            if not done and n == BURST_PACKETS_PER_TICK and burst.sent_bytes > BURST_CHUNK_BYTES:
                p.burst_complete = 1
                done = True
            self._reply(p, burst.target, ctx)
            if done:
                self._burst = None
                return

    def _fill_burst_packet(self, p: Payload, burst: _Burst) -> bool:
        """The next piece of the file into `p`; True if it ends the burst (a NAK)."""
        if burst.offset >= self._file_size:
            p.fail(FtpNak(Err.EOF))
            return True
        try:
            data = self._read_at(burst.offset, MAX_DATA)
        except OSError as err:
            p.fail(FtpNak(Err.FAIL_ERRNO, err.errno or errno.EIO))
            return True
        if not data:
            p.fail(FtpNak(Err.EOF))
            return True
        p.set_data(data)
        burst.offset += len(data)
        burst.sent_bytes += len(data)
        return False
