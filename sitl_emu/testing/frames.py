"""A MAVLink parser for scripted clients that decodes only the messages they read.

A client on a vehicle's API link hears ~450 messages a simulated second (PX4's onboard stream set) and reads a few
of them; decoding every one with pymavlink was most of a campaign case's CPU. `MessageFilter` reads each frame's
message id in its header (MAVLink 2: bytes 7-9, MAVLink 1: byte 5) and skips the frames of other messages unparsed.
The frames it does want go whole through pymavlink's own parser (robust parsing: checksum and crc_extra, length,
incompat flags; a bad frame is a BAD_DATA, as before), so what comes out is exactly what pymavlink alone would give.

    wanted = MessageFilter(("HEARTBEAT", "LOCAL_POSITION_NED", "COMMAND_ACK"))
    for msg in wanted.parse(datagram):
        ...

A message read now and then but sent often (GLOBAL_POSITION_INT, 50 Hz) can be kept instead (`keep_last`): only its
newest frame is kept, and decoded when `last(name)` asks for it.

A datagram holds whole frames (PX4 and sitl_emu send one message per datagram); a frame cut short at a datagram's
end is given to pymavlink with what follows it dropped, so it can never swallow the next datagram.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from pymavlink.dialects.v20 import development as dialect

__all__ = ["MessageFilter", "message_id"]

MAGIC_V1 = 0xFE
MAGIC_V2 = 0xFD
HEADER_V1 = 6  # magic, len, seq, sysid, compid, msgid
HEADER_V2 = 10  # magic, len, incompat, compat, seq, sysid, compid, msgid (3 bytes)
CHECKSUM = 2
SIGNATURE = 13  # link id, 6-byte timestamp, 6-byte signature, after the checksum of a signed frame
IFLAG_SIGNED = 0x01


def message_id(name: str) -> int:
    """The id of the message `name` (e.g. "LOCAL_POSITION_NED"); ValueError naming it if pymavlink has no such one."""
    msg_id = getattr(dialect, f"MAVLINK_MSG_ID_{name.upper()}", None)
    if not isinstance(msg_id, int):
        raise ValueError(f"pymavlink's development dialect has no message named {name}.")
    return msg_id


class MessageFilter:
    """Decodes the frames of the messages named (add() names more); skips every other frame undecoded."""

    def __init__(self, names: Iterable[str] = ()) -> None:
        self.wanted: set[int] = set()
        self.every = False  # add_all(): decode every frame (a recorder)
        self.skipped = 0  # frames not decoded (of those that reach parse(): a kernel prefilter drops others first)
        self._parser = _new_parser()
        self._kept: set[int] = set()  # keep_last(): the newest frame kept, decoded on demand
        self._newest: dict[int, bytes] = {}  # kept frames not decoded yet
        self._last: dict[int, Any] = {}  # the last valid message of each kept id
        self.add(*names)

    def add(self, *names: str) -> None:
        self.wanted.update(message_id(name) for name in names)

    def add_all(self) -> None:
        """Decode every message from now on, as pymavlink's parser alone does."""
        self.every = True

    def keep_last(self, *names: str) -> None:
        """Keep only the newest frame of these messages, decoded when last() asks (not returned by parse())."""
        self._kept.update(message_id(name) for name in names)

    def ids_read(self) -> frozenset[int] | None:
        """The message ids whose single frames parse() uses (wanted and kept); None when it decodes every frame.

        For a prefilter that drops the other single frames before they reach parse() (testing/kernel_filter.py)."""
        return None if self.every else frozenset(self.wanted | self._kept)

    def last(self, name: str) -> Any:
        """The newest valid message `name` of those kept (keep_last), decoded now if it is new; None before one."""
        msg_id = message_id(name)
        frame = self._newest.pop(msg_id, None)
        if frame is not None:
            self._remember([m for m in self._decode(frame) if m.get_type() != "BAD_DATA"])
        return self._last.get(msg_id)

    def parse(self, data: bytes) -> list[Any]:
        """The wanted messages of one datagram, in order (and BAD_DATA for a wanted frame that is not valid)."""
        if self.every:
            msgs = self._decode(data)
            self._remember(msgs)
            return msgs
        size = len(data)
        if size >= HEADER_V2 and data[0] == MAGIC_V2:  # the common case first: one MAVLink 2 frame per datagram
            signed = SIGNATURE if data[2] & IFLAG_SIGNED else 0
            if HEADER_V2 + data[1] + CHECKSUM + signed == size:
                out: list[Any] = []
                self._take(data, data[7] | data[8] << 8 | data[9] << 16, out)
                return out
        return self._parse_frames(data)

    def _parse_frames(self, data: bytes) -> list[Any]:
        out: list[Any] = []
        start, size = 0, len(data)
        while start < size:
            frame_end, msg_id = _frame_at(data, start)
            if frame_end < 0 or frame_end > size:  # not a frame start, or a frame cut short: pymavlink judges
                out.extend(m for m in self._decode(data[start:]) if _wanted_or_bad(m, self.wanted))
                break
            self._take(data[start:frame_end], msg_id, out)
            start = frame_end
        return out

    def _take(self, frame: bytes, msg_id: int, out: list[Any]) -> None:
        """One whole frame: decoded into `out` if wanted, kept if kept, else skipped."""
        if msg_id in self.wanted:
            out.extend(self._decode(frame))
        elif msg_id in self._kept:
            self._newest[msg_id] = frame
        else:
            self.skipped += 1

    def _remember(self, msgs: list[Any]) -> None:
        for msg in msgs:
            if msg.get_type() != "BAD_DATA" and msg.get_msgId() in self._kept:
                self._last[msg.get_msgId()] = msg

    def _decode(self, frames: bytes) -> list[Any]:
        parser = self._parser
        msgs = parser.parse_buffer(frames) or []
        if parser.buf_len() > 0:  # a frame cut short: dropped here, never joined to the next datagram
            self._parser = _new_parser()
            msgs.append(dialect.MAVLink_bad_data(bytearray(frames), "Frame cut short at the end of the datagram"))
        return msgs


def _frame_at(data: bytes, start: int) -> tuple[int, int]:
    """(end, message id) of the frame starting at `start`; (-1, -1) if no MAVLink frame starts there."""
    magic = data[start]
    if magic == MAGIC_V2 and start + HEADER_V2 <= len(data):
        signed = SIGNATURE if data[start + 2] & IFLAG_SIGNED else 0
        msg_id = data[start + 7] | data[start + 8] << 8 | data[start + 9] << 16
        return start + HEADER_V2 + data[start + 1] + CHECKSUM + signed, msg_id
    if magic == MAGIC_V1 and start + HEADER_V1 <= len(data):
        return start + HEADER_V1 + data[start + 1] + CHECKSUM, data[start + 5]
    return -1, -1


def _wanted_or_bad(msg: Any, wanted: set[int]) -> bool:
    return msg.get_type() == "BAD_DATA" or msg.get_msgId() in wanted


def _new_parser() -> Any:
    parser = dialect.MAVLink(None)
    parser.robust_parsing = True
    return parser
