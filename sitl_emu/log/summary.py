"""What a ULog file holds, in a few lines: duration, modes over time, max altitude and speed, logged texts.

Reads PX4's topic and field names (msg/versioned/VehicleStatus.msg, VehicleLocalPosition.msg), so it summarises the
files sitl-emu writes (sitl_emu/log/) and real PX4 logs alike: vehicle_status.nav_state, vehicle_local_position
x/y/z/vx/vy, and the logged (STATUSTEXT) messages. pyulog reads the file.
"""

from __future__ import annotations

import contextlib
import io
import math
import struct
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sitl_emu.cli.extras import install_command
from sitl_emu.px4 import UI_NAMES, NavState

__all__ = ["LogError", "LogSummary", "ModeSpan", "Text", "format_summary", "mode_label", "read_ulog",
           "series", "summarise"]

US = 1e-6
PLOT_PACKAGES = "'pyulog>=1.0' 'matplotlib>=3.7'"  # the plot extra (pyproject.toml), where there is no clone
HEADER_LEN = 16  # ULog file header: magic, version, timestamp
MESSAGE_HEADER = struct.Struct("<HB")  # every message: uint16 msg_size, uint8 msg_type (PX4 docs, ULog file format)


class LogError(Exception):
    """The file cannot be summarised; str() is one sentence for the user."""


@dataclass(frozen=True, slots=True)
class ModeSpan:
    start_s: float  # since the start of the log
    nav_state: int
    name: str


@dataclass(frozen=True, slots=True)
class Text:
    time_s: float
    level: str
    text: str


@dataclass(frozen=True, slots=True)
class LogSummary:
    path: Path
    sys_name: str
    ver_sw: str
    duration_s: float
    modes: tuple[ModeSpan, ...]
    max_alt_m: float | None  # above the first logged position
    max_hspeed_mps: float | None
    texts: tuple[Text, ...]


def read_ulog(path: str | Path) -> Any:
    """The pyulog ULog of `path`; LogError for a missing, unreadable, non-ULog or truncated file."""
    try:
        from pyulog import ULog  # the extras `plot` and `test` have it; imported late to keep the CLI light
        from pyulog.exceptions import ULogException
    except ImportError:
        raise LogError("Reading ULog files needs pyulog, which is not installed: "
                       f"{install_command('plot', PLOT_PACKAGES)}") from None

    path = Path(path)
    if not path.exists():
        raise LogError(f"{path}: no such file.")
    try:
        with contextlib.redirect_stdout(io.StringIO()):  # pyulog prints its warnings
            ulog = ULog(str(path))
        complete = _ends_with_a_whole_message(path)
    except (ULogException, ValueError, IndexError, struct.error) as err:
        raise LogError(f"{path} is not a ULog file ({err}).") from None
    except OSError as err:
        raise LogError(f"{path}: cannot read it ({err.strerror or err}).") from None
    if ulog.file_corruption or not complete or not ulog.data_list:
        raise LogError(f"{path} is a truncated or damaged ULog file (it ends part way through its messages).")
    return ulog


def _ends_with_a_whole_message(path: Path) -> bool:
    """Whether the messages after the file header end exactly at the end of the file (pyulog drops a cut-off last
    message without a word)."""
    data = path.read_bytes()
    at = HEADER_LEN
    while at + MESSAGE_HEADER.size <= len(data):
        size, _ = MESSAGE_HEADER.unpack_from(data, at)
        at += MESSAGE_HEADER.size + size
    return at == len(data)


def mode_label(nav_state: int) -> str:
    """PX4's name for a nav_state (src/lib/modes/ui.hpp), or the number for one this emulator does not know."""
    try:
        return UI_NAMES[NavState(nav_state)]
    except (ValueError, KeyError):
        return f"nav_state {nav_state}"


def series(ulog: Any, topic: str, field: str) -> tuple[np.ndarray, np.ndarray] | None:
    """(times in s since the log's start, values) of topic.field (first instance), None when it is not logged."""
    try:
        data = ulog.get_dataset(topic, 0).data
    except (KeyError, IndexError, StopIteration):
        return None
    if field not in data or len(data["timestamp"]) == 0:
        return None
    # int64 first: a topic's first sample can predate the log's start (PX4 logs the last published one), and the
    # uint64 difference would wrap
    since_start = data["timestamp"].astype(np.int64) - np.int64(ulog.start_timestamp)
    return since_start * US, np.asarray(data[field], dtype=float)


def summarise(ulog: Any, path: str | Path = "") -> LogSummary:
    info = ulog.msg_info_dict
    return LogSummary(
        path=Path(path), sys_name=str(info.get("sys_name", "?")), ver_sw=str(info.get("ver_sw", "?")),
        duration_s=(ulog.last_timestamp - ulog.start_timestamp) * US, modes=_modes(ulog),
        max_alt_m=_max_alt(ulog), max_hspeed_mps=_max_hspeed(ulog), texts=_texts(ulog))


def _modes(ulog: Any) -> tuple[ModeSpan, ...]:
    nav = series(ulog, "vehicle_status", "nav_state")
    if nav is None:
        return ()
    spans: list[ModeSpan] = []
    for t, value in zip(*nav, strict=True):
        if not spans or spans[-1].nav_state != int(value):
            spans.append(ModeSpan(float(t), int(value), mode_label(int(value))))
    return tuple(spans)


def _max_alt(ulog: Any) -> float | None:
    z = series(ulog, "vehicle_local_position", "z")
    if z is None:
        return None
    finite = z[1][np.isfinite(z[1])]
    return float(finite[0] - finite.min()) if finite.size else None  # NED: up is -z


def _max_hspeed(ulog: Any) -> float | None:
    vx, vy = (series(ulog, "vehicle_local_position", f) for f in ("vx", "vy"))
    if vx is None or vy is None:
        return None
    speed = np.hypot(vx[1], vy[1])
    speed = speed[np.isfinite(speed)]
    return float(speed.max()) if speed.size else None


def _texts(ulog: Any) -> tuple[Text, ...]:
    return tuple(Text((m.timestamp - ulog.start_timestamp) * US, m.log_level_str(), m.message.rstrip())
                 for m in ulog.logged_messages)


def _clock(seconds: float) -> str:
    minutes, s = divmod(max(seconds, 0.0), 60.0)
    return f"{int(minutes):02d}:{s:06.3f}"


def _number(value: float | None, unit: str) -> str:
    return "not logged" if value is None or not math.isfinite(value) else f"{value:.2f} {unit}"


def format_summary(s: LogSummary) -> str:
    lines = [f"{s.path}: {s.sys_name} {s.ver_sw}",
             f"Duration:               {_clock(s.duration_s)} ({s.duration_s:.1f} s)",
             f"Max altitude over start: {_number(s.max_alt_m, 'm')}",
             f"Max horizontal speed:   {_number(s.max_hspeed_mps, 'm/s')}",
             "Modes:" if s.modes else "Modes: vehicle_status not logged"]
    lines += [f"  {_clock(m.start_s)}  {m.name}" for m in s.modes]
    lines.append(f"Texts ({len(s.texts)}):" if s.texts else "Texts: none")
    lines += [f"  {_clock(t.time_s)}  {t.level:<8} {t.text}" for t in s.texts]
    return "\n".join(lines)
