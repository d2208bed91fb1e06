"""A MAVLink FTP client for the tests: real FILE_TRANSFER_PROTOCOL datagrams to a node stepped in lockstep (Harness).

It speaks the payload layout of sitl_emu/mavlink/protocols/ftp.py (which MAVSDK's and QGC's clients share) and
waits, tick by tick of simulated time, for the reply whose seq is the request's + 1.
"""

from __future__ import annotations

from typing import Any

from sitl_emu.mavlink.protocols.ftp import MAX_DATA, Err, Op, Payload
from support.fakes import Harness

MAX_TICKS = 50  # a reply comes in the tick after the request; bursts take more


def request_payload(opcode: int, data: bytes = b"", *, seq: int = 0, session: int = 0, offset: int = 0,
                    size: int | None = None) -> bytes:
    """The 251 payload bytes of a request (size defaults to len(data); data may be longer than the size says)."""
    body = bytearray(max(MAX_DATA, len(data)))
    body[:len(data)] = data
    p = Payload(seq, session, opcode, len(data) if size is None else size, 0, 0, 0, offset, body[:MAX_DATA])
    return p.pack()


class FtpClient:
    """Requests on the harness's GCS client (sysid 255, compid 190) to the vehicle (1, 1)."""

    def __init__(self, harness: Harness, target: tuple[int, int] = (1, 1)) -> None:
        self.h = harness
        self.target = target
        self.seq = 0

    def send(self, opcode: int, data: bytes = b"", *, seq: int | None = None, **fields: Any) -> int:
        """Send one request; returns its seq (the client's counter goes on from it)."""
        seq = self.seq if seq is None else seq
        self.seq = (seq + 1) & 0xFFFF
        payload = request_payload(opcode, data, seq=seq, **fields)
        self.h.gcs.send(self.h.gcs.mav.file_transfer_protocol_encode(0, *self.target, payload))
        return seq

    def replies(self, ticks: int = MAX_TICKS, until: int | None = None) -> list[Payload]:
        """FTP payloads from the vehicle over `ticks` ticks (or until one with seq `until` came)."""
        got: list[Payload] = []
        for _ in range(ticks):
            self.h.vehicle.step()
            self.h.node.step_io(self.h.vehicle.time_us)
            for msg in self.h.gcs.drain():
                if msg.get_type() == "FILE_TRANSFER_PROTOCOL" and msg.get_srcSystem() == self.h.vehicle.sysid:
                    got.append(Payload.unpack(bytes(msg.payload)))
            if until is not None and any(p.seq == until for p in got):
                break
        return got

    def call(self, opcode: int, data: bytes = b"", **fields: Any) -> Payload:
        """One request and its one reply."""
        seq = self.send(opcode, data, **fields)
        replies = self.replies(until=(seq + 1) & 0xFFFF)
        assert len(replies) == 1, f"expected one reply to {Op(opcode).name}, got {replies}"
        return replies[0]

    def ok(self, opcode: int, data: bytes = b"", **fields: Any) -> Payload:
        reply = self.call(opcode, data, **fields)
        assert reply.opcode == Op.ACK, f"{Op(opcode).name} {data!r}: {describe(reply)}"
        return reply

    def nak(self, opcode: int, data: bytes = b"", **fields: Any) -> tuple[Err, int]:
        """The NAK's error code and errno (0 when it has none)."""
        reply = self.call(opcode, data, **fields)
        assert reply.opcode == Op.NAK, f"{Op(opcode).name} {data!r} was acked: {describe(reply)}"
        return Err(reply.data[0]), reply.data[1] if reply.size == 2 else 0

    # --- whole operations -------------------------------------------------------------------------------------
    def list_dir(self, path: bytes) -> list[bytes]:
        """Every entry, paging by offset as MAVSDK does until the NAK EOF (or an empty ack)."""
        entries: list[bytes] = []
        while True:
            reply = self.call(Op.LIST_DIRECTORY, path + b"\0", offset=len(entries))
            if reply.opcode == Op.NAK:
                assert reply.data[0] == Err.EOF, describe(reply)
                return entries
            if reply.size == 0:
                return entries
            entries += bytes(reply.data[:reply.size]).split(b"\0")[:-1]

    def read_file(self, path: bytes) -> bytes:
        size = int.from_bytes(self.ok(Op.OPEN_FILE_RO, path + b"\0").data[:4], "little")
        out = bytearray()
        while len(out) < size:
            reply = self.ok(Op.READ_FILE, offset=len(out), size=min(MAX_DATA, size - len(out)))
            out += reply.data[:reply.size]
        self.ok(Op.TERMINATE_SESSION)
        return bytes(out)

    def write_file(self, path: bytes, content: bytes) -> None:
        self.ok(Op.CREATE_FILE, path + b"\0")
        for offset in range(0, len(content), MAX_DATA):
            chunk = content[offset:offset + MAX_DATA]
            assert int.from_bytes(self.ok(Op.WRITE_FILE, chunk, offset=offset).data[:4], "little") == len(chunk)
        self.ok(Op.TERMINATE_SESSION)


def describe(p: Payload) -> str:
    op = Op(p.opcode).name if p.opcode in Op._value2member_map_ else str(p.opcode)
    extra = f" {Err(p.data[0]).name}" if p.opcode == Op.NAK and p.data[0] in Err._value2member_map_ else ""
    return f"seq {p.seq} {op}{extra} req {p.req_opcode} size {p.size} offset {p.offset}"
