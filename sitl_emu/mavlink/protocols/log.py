"""The log download protocol (LOG_REQUEST_LIST / LOG_ENTRY, LOG_REQUEST_DATA / LOG_DATA, LOG_REQUEST_END, LOG_ERASE).

Source: PX4 src/modules/mavlink/mavlink_log_handler.cpp. Its logs are the regular files in the subdirectories of
its log directory (log/<date>/<time>.ulg), listed with their size and modification time; the id of a log is its
place in that list.
- LOG_REQUEST_LIST lists anew. With no log, the answer is one LOG_ENTRY {id 0, num_logs 0, last_log_num 0,
  time_utc 0, size 0}: what PX4's handler sent for years and the MAVLink spec made the rule (common.xml,
  LOG_REQUEST_LIST), and what MAVSDK's LogFiles reads as "no log files" instead of waiting for a timeout. (The
  handler PX4 rewrote in 2024 sends nothing at all then.) With logs, LOG_ENTRY streams from id `start` to the
  last one, num_logs the count, last_log_num `end` (the count when `end` is 0xFFFF), as the rewritten handler does.
- LOG_REQUEST_DATA {id, ofs, count}, after a listing, streams LOG_DATA in 90-byte pieces (the file's last one
  shorter) from `ofs` until `count` bytes are covered or the file ends; an unknown id, an offset at or past the
  end, or no listing yet: nothing (and what was streaming stops). PX4 sums ofs + count in 32 bits: a count near
  0xFFFFFFFF from an offset past 0 ends the piece after its first LOG_DATA. A new request replaces the one
  streaming, whether or not the client read it to the end.
- LOG_REQUEST_END stops what is streaming; LOG_ERASE stops it and erases every log.
PX4's handler looks at no target; this one answers only requests for its own system (or system 0), since several
emulated vehicles may share one process.

The logs come from LogProtocol.source: NoLogs until the emulator writes logs; DirectoryLogSource reads PX4's layout.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any, ClassVar, Protocol, cast

if TYPE_CHECKING:
    from pymavlink.dialects.v20.development import MAVLink_message

    from sitl_emu.mavlink.context import LinkContext

LOG_DATA_LEN = 90  # LOG_DATA.data
LIST_ALL = 0xFFFF  # LOG_REQUEST_LIST.end: up to the last log
# PX4 sends until its 1500-byte UDP budget per 1.5 ms loop pass is spent: about these many per 4 ms tick
ENTRIES_PER_TICK = 64
DATA_PER_TICK = 32


@dataclass(frozen=True, slots=True)
class LogFile:
    path: Path
    size_bytes: int
    time_utc: int  # s since 1970: the file's modification time, as PX4 lists it


class LogSource(Protocol):
    def list_logs(self) -> list[LogFile]: ...

    def erase_all(self) -> None: ...


class NoLogs:
    """No log at all: what a vehicle that writes no logs has."""

    def list_logs(self) -> list[LogFile]:
        return []

    def erase_all(self) -> None:
        """Nothing to erase."""


class DirectoryLogSource:
    """PX4's layout: the regular files in the subdirectories of `directory`, in name order."""

    def __init__(self, directory: str | os.PathLike[str]) -> None:
        self.directory = Path(directory)

    def list_logs(self) -> list[LogFile]:
        if not self.directory.is_dir():
            return []
        logs = []
        for session in sorted(p for p in self.directory.iterdir() if p.is_dir() and not p.is_symlink()):
            for path in sorted(session.iterdir()):
                if path.is_file() and not path.is_symlink():
                    st = path.stat()
                    logs.append(LogFile(path, st.st_size, int(st.st_mtime)))
        return logs

    def erase_all(self) -> None:
        for log in self.list_logs():
            log.path.unlink(missing_ok=True)


@dataclass(slots=True)
class _Listing:
    next_id: int
    last_log_num: int


@dataclass(slots=True)
class _OpenLog:
    log_id: int
    file: IO[bytes]
    size_bytes: int
    offset: int = 0
    end: int = 0  # the requested piece ends here (ofs + count)
    sending: bool = False


class LogProtocol:
    """One instance per link, as PX4 runs one log handler per mavlink instance."""

    MESSAGES: ClassVar[tuple[str, ...]] = ("LOG_REQUEST_LIST", "LOG_REQUEST_DATA", "LOG_REQUEST_END", "LOG_ERASE")
    source: ClassVar[LogSource] = NoLogs()

    @classmethod
    def with_source(cls, source: LogSource) -> type[LogProtocol]:
        """This protocol serving the logs of `source` (a handler class, for a node's handler list)."""
        return cast("type[LogProtocol]", type(cls.__name__, (cls,), {"source": source}))

    def __init__(self) -> None:
        self._logs: list[LogFile] | None = None  # None until a list was requested
        self._listing: _Listing | None = None
        self._open: _OpenLog | None = None
        self._handlers: dict[str, Callable[[Any, LinkContext], None]] = {
            "LOG_REQUEST_LIST": self._on_request_list,
            "LOG_REQUEST_DATA": self._on_request_data,
            "LOG_REQUEST_END": lambda msg, ctx: self._stop(),
            "LOG_ERASE": self._on_erase,
        }

    def handle(self, msg: MAVLink_message, ctx: LinkContext) -> None:
        if getattr(msg, "target_system", 0) in (0, ctx.sysid):
            self._handlers[msg.get_type()](msg, ctx)

    def _on_request_list(self, msg: Any, ctx: LinkContext) -> None:
        self._stop()
        self._logs = self.source.list_logs()
        if not self._logs:
            ctx.send(ctx.encoder.log_entry_encode(0, 0, 0, 0, 0))
            return
        last = len(self._logs) if msg.end == LIST_ALL else msg.end
        self._listing = _Listing(msg.start, last)

    def _on_request_data(self, msg: Any, ctx: LinkContext) -> None:
        self._listing = None
        logs = self._logs or []
        if msg.id >= len(logs):
            self._stop()
            return
        if self._open is None or self._open.log_id != msg.id:
            self._stop()
            try:
                self._open = _OpenLog(msg.id, logs[msg.id].path.open("rb"), logs[msg.id].size_bytes)
            except OSError:
                return
        log = self._open
        # PX4 adds ofs and count as uint32_t (state_sending_data's chunk_finished), so a huge count from an offset
        # past 0 wraps to an end just before the offset: one LOG_DATA, then it waits for the next request
        end = (msg.ofs + msg.count) & 0xFFFFFFFF
        log.offset, log.end, log.sending = msg.ofs, end, msg.ofs < log.size_bytes

    def _on_erase(self, msg: Any, ctx: LinkContext) -> None:
        self._stop()
        self._logs = []
        self.source.erase_all()

    def _stop(self) -> None:
        self._listing = None
        if self._open is not None:
            self._open.file.close()
            self._open = None

    # --- streaming ---------------------------------------------------------------------------------------------
    def tick(self, ctx: LinkContext) -> bool:
        """Stream the listing and the requested data; False when nothing is left to send (idle until a request)."""
        if self._listing is not None:
            self._send_entries(self._listing, ctx)
        if self._open is not None and self._open.sending:
            self._send_data(self._open, ctx)
        return self._listing is not None or (self._open is not None and self._open.sending)

    def _send_entries(self, listing: _Listing, ctx: LinkContext) -> None:
        logs = self._logs or []
        for _ in range(ENTRIES_PER_TICK):
            if listing.next_id >= len(logs):
                self._listing = None
                return
            log = logs[listing.next_id]
            ctx.send(ctx.encoder.log_entry_encode(listing.next_id, len(logs), listing.last_log_num & 0xFFFF,
                                              log.time_utc & 0xFFFFFFFF, log.size_bytes & 0xFFFFFFFF))
            listing.next_id += 1

    def _send_data(self, log: _OpenLog, ctx: LinkContext) -> None:
        """LOG_DATA from log.offset until the requested piece or the file ends (the file stays open for the next)."""
        for _ in range(DATA_PER_TICK):
            log.file.seek(log.offset)
            data = log.file.read(min(LOG_DATA_LEN, max(log.size_bytes - log.offset, 0)))
            ctx.send(ctx.encoder.log_data_encode(log.log_id, log.offset, len(data), data.ljust(LOG_DATA_LEN, b"\0")))
            log.offset += len(data)
            if not data or log.offset >= min(log.end, log.size_bytes):
                log.sending = False
                return
