"""One vehicle's logger: ULog files as PX4's logger writes them, when SDLOG_MODE says (read when logging starts).

SDLOG_MODE (logger.cpp start_stop_logging, _log_on_start): 0 a file per flight, from arming to disarming; 1 (PX4
SITL's value) the first file from boot to the first disarming, then one per flight, so the first arming sends no
"[logger]" text (../shared/reference/px4-mission cases.json: flight1.arm has none, flight2.arm has); 2 one file from
boot to shutdown; 4 one file from the first arming to shutdown; -1 and 3 (an RC AUX1 switch, which the emulator
does not have) none.

Source: PX4 src/modules/logger/logger.cpp. On arming it names the file from the UTC time
(`<log dir>/YYYY-MM-DD/HH_MM_SS.ulg`, get_log_file_name), sends "[logger] <file>" (mavlink_log_info, also an
event, so the STATUSTEXT ends in a tab) and writes the header, the version infos, the formats, the parameters and
their defaults, and the subscriptions (start_log_file); then each topic at its interval, every STATUSTEXT as a
logged string ('L', the log_message topic) and a sync message every 500 ms; parameters changed in flight as new
'P' messages; on disarming it closes the file.

The UTC time is the vehicle's own: the wall clock when it started plus the simulated time, what its SYSTEM_TIME and
GPS report, as PX4 SITL names its logs after its GPS time. Timestamps in the file are the vehicle's boot time in µs
(PX4's hrt_absolute_time).

This runs on the runtime side, in the tick loop: `tick(now_us)` after each vehicle step (runtime/node.py). The
vehicle knows nothing of it. A directory that cannot be created or a file that cannot be written (full disk) ends
that flight's log with one warning; the vehicle flies on, and the next arming tries again.
"""

from __future__ import annotations

import contextlib
import logging
import os
from collections.abc import Callable, Hashable
from datetime import datetime, timezone
from pathlib import Path
from typing import IO, Any, Final

from sitl_emu.log import ulog_writer as ulog
from sitl_emu.log.info import parameter_messages, version_infos
from sitl_emu.log.topics import Inputs, Topic, default_topics
from sitl_emu.params import ParamType
from sitl_emu.px4 import Severity
from sitl_emu.vehicle.vehicle import Vehicle

log = logging.getLogger(__name__)

SYNC_INTERVAL_US: Final = 500_000  # logger.cpp: "Add sync magic" every 500 ms
WHILE_ARMED, BOOT_UNTIL_DISARM, BOOT_UNTIL_SHUTDOWN, FIRST_ARM_UNTIL_SHUTDOWN = 0, 1, 2, 4  # SDLOG_MODE
BUFFER_BYTES: Final = 64 * 1024
Opener = Callable[[Path], IO[bytes]]


def _open_file(path: Path) -> IO[bytes]:
    return path.open("xb", buffering=BUFFER_BYTES)


def log_path(directory: Path, utc_us: int) -> Path:
    """PX4's name for a log started at `utc_us`: <directory>/YYYY-MM-DD/HH_MM_SS.ulg."""
    t = datetime.fromtimestamp(utc_us / 1e6, tz=timezone.utc)
    return directory / t.strftime("%Y-%m-%d") / t.strftime("%H_%M_%S.ulg")


def shown_path(path: Path) -> str:
    """The file as the "[logger]" text names it: relative paths from "./", as PX4 SITL's "./log/..."."""
    text = str(path)
    return text if path.is_absolute() or text.startswith(".") else f"./{text}"


class _Schedule:
    """When a topic is next due: an interval grid, and a state whose change is written at once; and how its 'D'
    message is packed (ulog_writer.DataPacker)."""

    __slots__ = ("next_us", "pack", "state")

    def __init__(self, pack: Callable[[Any], bytes]) -> None:
        self.next_us = 0
        self.state: Hashable = object()
        self.pack = pack


def _changed(sched: _Schedule, state: Hashable) -> bool:
    """Whether a watched state differs from the one last written: the same object is the same state (the home
    position is one object until it is set again), so the equality test, slow for a dataclass, runs only on a new
    object."""
    return state is not sched.state and state != sched.state


class FlightLogger:
    """Writes vehicle `node.vehicle`'s flights under `directory` (module docstring)."""

    def __init__(self, node: Any, directory: str | os.PathLike[str], *, opener: Opener | None = None) -> None:
        self.node = node
        self.directory = Path(directory)
        self.opener = opener
        self.topics: list[Topic] = default_topics()
        self.files: list[Path] = []  # the logs written, in order
        self.path: Path | None = None  # the log being written
        self._file: IO[bytes] | None = None
        self._pending = bytearray()  # written, not yet in the file (_write)
        self._failed = False  # this flight's log failed: wait for the next arming
        self._last_us = -1
        self._event_seq = 0
        self._params: dict[str, float] = {}
        self._params_watch = node.vehicle.params.changes.watch()  # params/changes.py; again at each log's start
        self._next_sync_us = 0
        self._plan: list[tuple[Topic, _Schedule]] = []  # in msg_id order: the topic, when it is next due
        self._inputs: Inputs | None = None  # what the topics read, from the start of a log
        params = node.vehicle.params
        self.mode = int(params.get("SDLOG_MODE")) if "SDLOG_MODE" in params else WHILE_ARMED
        self._ever_armed = False

    @property
    def writing(self) -> bool:
        return self._file is not None

    def tick(self, now_us: int) -> None:
        """Called after every vehicle step (and maybe again at the same instant: ignored)."""
        if now_us == self._last_us:
            return
        self._last_us = now_us
        vehicle: Vehicle = self.node.vehicle  # (typed: compiled, its attributes are read natively)
        armed = vehicle.commander.armed
        if not self._wanted(armed):
            self._failed = False
            if self._file is not None:
                self._record()  # the disarmed state and its texts end the log
                self.close()
            self._event_seq = vehicle.last_event_seq  # texts from here on: those of the arming go in the new log
            return
        if self._file is None and not self._failed:
            self._start(vehicle.time_us)
        if self._file is not None:
            self._record()

    def _wanted(self, armed: bool) -> bool:
        """Whether a log is open now, by SDLOG_MODE (module docstring)."""
        first_flight = not self._ever_armed
        self._ever_armed = self._ever_armed or armed
        if self.mode == WHILE_ARMED:
            return armed
        if self.mode == BOOT_UNTIL_DISARM:
            return armed or first_flight
        if self.mode == BOOT_UNTIL_SHUTDOWN:
            return True
        return self.mode == FIRST_ARM_UNTIL_SHUTDOWN and self._ever_armed

    def close(self) -> None:
        """End the log being written (disarm, shutdown)."""
        if self._file is not None:
            self._flush()  # (a failure says so and closes the file)
        f, self._file = self._file, None
        if f is None:
            return
        try:
            f.close()
        except OSError as err:
            self._fail(err)
        self.path = None

    # --- starting a log ----------------------------------------------------------------------------------------
    def _start(self, now_us: int) -> None:
        path = log_path(self.directory, self.node.epoch_unix_us + now_us)
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            path = self._free_name(path)
            self._file = (self.opener or _open_file)(path)
        except OSError as err:
            self.path = path
            self._fail(err)
            return
        self.path = path
        self.files.append(path)
        self.node.vehicle.report(Severity.INFO, "logger", f"[logger] {shown_path(path)}")
        self._write(self._preamble(now_us))
        self._plan = [(topic, _Schedule(ulog.DataPacker(topic.format, msg_id, topic.values.names)))
                      for msg_id, topic in enumerate(self.topics)]
        self._inputs = Inputs(self.node.vehicle, int(self.node.vehicle.sysid), self.node.snapshot)
        self._next_sync_us = now_us
        self._log_texts(self.node.vehicle.events_after(self._event_seq))  # the arming's texts and "[logger] ..."

    @staticmethod
    def _free_name(path: Path) -> Path:
        """Two flights within one second: PX4 would overwrite; keep both (HH_MM_SS_1.ulg)."""
        n = 0
        candidate = path
        while candidate.exists():
            n += 1
            candidate = path.with_name(f"{path.stem}_{n}{path.suffix}")
        return candidate

    def _preamble(self, now_us: int) -> bytes:
        vehicle = self.node.vehicle
        formats = [t.format for t in self.topics]
        definitions, subscriptions = ulog.formats_and_subscriptions(formats)
        infos = version_infos(int(vehicle.sysid), self.node.epoch_unix_us)
        params = vehicle.params
        self._params = {d.name: params.get(d.name) for d in params}
        self._params_watch = params.changes.watch()  # params/changes.py
        return b"".join((ulog.file_header(now_us), ulog.flag_bits(), infos, definitions,
                         parameter_messages(params), subscriptions))

    # --- every tick --------------------------------------------------------------------------------------------
    def _record(self) -> None:
        """This tick's texts, changed parameters, due topics (a snapshot only if one of them reads it) and sync."""
        inputs = self._inputs
        assert inputs is not None  # set by _start
        vehicle = inputs.vehicle
        inputs.new_tick()
        events = vehicle.events_after(self._event_seq)
        if events:
            self._log_texts(events)
        if self._params_watch.changed():
            self._write(self._changed_params())
        now = inputs.time_us
        pending = self._pending
        for topic, sched in self._plan:
            state = topic.state
            if now < sched.next_us and (state is None or not _changed(sched, state(inputs))):
                continue
            if state is not None:
                sched.state = state(inputs)
            sched.next_us = sched.next_us + topic.interval_us
            if sched.next_us <= now:  # (after a pause, a change, or an interval shorter than a tick)
                sched.next_us = now + topic.interval_us
            values = topic.values.read(inputs)
            if values is not None:
                pending += sched.pack(values)
        if now >= self._next_sync_us:
            pending += ulog.sync()
            self._next_sync_us = now + SYNC_INTERVAL_US
        if len(pending) >= BUFFER_BYTES:
            self._flush()

    def _log_texts(self, events: list[Any]) -> None:
        """'L' messages for the STATUSTEXTs among `events` (level: their MAVLink severity, as PX4's log_message)."""
        if events:
            self._event_seq = events[-1].seq
        out = b"".join(ulog.log_text(int(e.severity), e.time_us, e.statustext_text)
                       for e in events if e.statustext)
        if out:
            self._write(out)

    def _changed_params(self) -> bytes:
        params = self.node.vehicle.params
        out = []
        for d in params:
            value = params.get(d.name)
            if self._params.get(d.name) != value:
                self._params[d.name] = value
                out.append(ulog.parameter(d.name, value, d.type is ParamType.INT32))
        return b"".join(out)

    def _write(self, data: bytes) -> None:
        """To the file in BUFFER_BYTES chunks (a write per tick cost more than packing a message)."""
        if self._file is None:
            return
        self._pending += data
        if len(self._pending) >= BUFFER_BYTES:
            self._flush()

    def _flush(self) -> None:
        if self._file is not None:
            try:
                self._file.write(self._pending)
            except OSError as err:
                self._fail(err)
        self._pending.clear()

    def _fail(self, err: OSError) -> None:
        """One warning; the rest of this flight is not logged."""
        self._failed = True
        self._pending.clear()
        f, self._file = self._file, None
        if f is not None:
            with contextlib.suppress(OSError):  # the buffered rest cannot be written either: already said
                f.close()
        where = self.path if self.path is not None else self.directory
        log.warning("Cannot write the flight log %s (%s); the flight goes on without a log.", where,
                    err.strerror or err)
