"""The live view of a flight: a block redrawn in place ~10 times a second on a terminal (link, mode, armed,
position, setpoint, stick bars, fence margin, the vehicle's last STATUSTEXTs), with joyfly's messages scrolling
above it. Without a terminal (a pipe, CI, a log file): plain lines, one per state change and at most one a second.
"""

from __future__ import annotations

import math
from typing import TextIO

from joyfly.session.core import FlightStats, Level, Note, Phase, SessionView
from joyfly.session.fence_watch import FENCE_TOLERANCE_M
from joyfly.term import LiveBlock
from joyfly.types import StickCommand

LIVE_PERIOD_S = 0.1
PLAIN_PERIOD_S = 1.0
_LANDED = {0: "?", 1: "on ground", 2: "in air", 3: "taking off", 4: "landing"}


def bar(value: float, half_width: int = 5) -> str:
    """A centred bar for -1..1: `[   |##  ]`."""
    n = round(max(-1.0, min(1.0, value)) * half_width)
    left = " " * (half_width + min(n, 0)) + "#" * -min(n, 0)
    right = "#" * max(n, 0) + " " * (half_width - max(n, 0))
    return f"[{left}|{right}]"


def fmt_vec(v: tuple[float, float, float] | None) -> str:
    return "(   -   ,    -   ,    -   )" if v is None else f"({v[0]:+7.2f}, {v[1]:+7.2f}, {v[2]:+7.2f})"


def fmt_margin(margin_m: float | None, alert: str = "") -> str:
    """The fence margin: "-" unknown (no home yet), "off", metres inside (+), on the fence, or OUTSIDE it (`alert`:
    the breach under way, e.g. "BREACH: land in 3 s")."""
    if margin_m is None:
        return "-"
    if math.isinf(margin_m):
        return "off"
    mark = "" if margin_m >= 0 else "  on the fence" if margin_m >= -FENCE_TOLERANCE_M else "  OUTSIDE"
    return f"{margin_m:+.2f} m{f'  {alert}' if alert and margin_m < 0 else mark}"


def _margin(view: SessionView) -> float | None:
    """The vehicle's fence margin now (None: no position, or no home for this flight yet)."""
    pos = view.pos_ned_m
    return view.fence.margin_m(pos) if pos is not None and view.home_known else None


def stick_line(cmd: StickCommand) -> str:
    up = cmd.up if cmd.up is not None else (2 * cmd.throttle_abs - 1 if cmd.throttle_abs is not None else 0.0)
    pressed = ",".join(sorted(a.value for a in cmd.pressed)) or "-"
    return (f"fwd {bar(cmd.forward)} right {bar(cmd.right)} up {bar(up)} yaw {bar(cmd.yaw)}  buttons {pressed}")


def _link_word(view: SessionView) -> str:
    return "ok" if view.link_ok else ("waiting" if view.phase is Phase.CONNECTING or not view.heard else "LOST")


def _sent_line(view: SessionView) -> str:
    """What joyfly sends: the OFFBOARD setpoint, or the MANUAL_CONTROL sticks (x, y, z, r) in the manual modes."""
    if view.control != "OFFBOARD":
        sent = view.manual.describe() if view.manual is not None else "-"
        return f"sticks sent  {sent}   (MANUAL_CONTROL, flying {view.control})"
    sp = view.setpoint
    return f"setpoint NED {fmt_vec(sp.pos_ned_m if sp else None)} m   yaw {math.degrees(sp.yaw_rad) if sp else 0:+6.1f}"


def render(view: SessionView) -> list[str]:
    """The live block for one view snapshot."""
    link = "waiting" if _link_word(view) == "waiting" else _link_word(view).upper()
    pos = view.pos_ned_m
    margin = _margin(view)
    stream = "streaming" if view.streaming else "not streaming"
    what = "setpoints" if view.control == "OFFBOARD" else "MANUAL_CONTROL"
    joy = "ok" if view.joystick_ok else "LOST (holding)" if view.phase is Phase.FLYING else "LOST"
    lines = [
        f"t {view.time_s:7.1f} s  {view.phase_text or view.phase.value:<28} link {link:<4} ({view.link_description})",
        f"mode {view.mode:<14} {'ARMED' if view.armed else 'disarmed':<9} {_LANDED.get(view.landed_state, '?'):<10}"
        f" {what} {stream}",
        f"position NED {fmt_vec(pos)} m   alt {_alt(view)}",
        _sent_line(view),
        f"fence margin {fmt_margin(margin, view.fence_alert)}   closest {fmt_margin(view.stats.min_fence_margin_m)}   "
        f"joystick {joy}",
        stick_line(view.stick),
    ]
    lines += [f"vehicle: {text}" for text in view.statustexts[-3:]]
    return lines


def _alt(view: SessionView) -> str:
    pos = view.pos_ned_m
    return f"{view.fence.alt_m(pos):5.2f} m" if pos is not None and view.home_known else "  -"


def breach_words(stats: FlightStats) -> str:
    """How often the vehicle went outside the fence, and how far: "once, 7.62 m outside at the deepest"."""
    times = "once" if stats.fence_breaches == 1 else f"{stats.fence_breaches} times"
    return f"{times}, {stats.deepest_breach_m:.2f} m outside at the deepest"


def fence_line(stats: FlightStats) -> str:
    """The summary's fence line: the breaches and the deepest, or how close the vehicle came."""
    if stats.fence_breaches:
        return f"fence breached        {breach_words(stats)}"
    closest = stats.min_fence_margin_m
    if math.isinf(closest):
        return "closest to the fence  n/a"
    if closest < 0:
        return (f"closest to the fence  {-closest:.2f} m past it, within joyfly's {FENCE_TOLERANCE_M:g} m "
                "tolerance: no breach")
    return f"closest to the fence  {closest:.2f} m inside"


def summary_lines(stats: FlightStats, control: str = "OFFBOARD", extra: list[str] | None = None) -> list[str]:
    """The flight's summary: distance, the fence (breaches, or the closest approach), time in joyfly's mode
    (`control`), the lines of the way of flying (`extra`), and the highest altitude (always the last line)."""
    return [
        f"distance flown        {stats.distance_m:6.1f} m",
        fence_line(stats),
        f"{'time in ' + control:<22}{stats.control_time_s:6.1f} s",
        *(extra or []),
        f"highest               {stats.max_alt_m:6.1f} m above home",
    ]


class LiveDashboard:
    """For a terminal: notes scroll, the status block stays at the bottom, redrawn at most 10 times a second."""

    def __init__(self, out: TextIO) -> None:
        self.out = out
        self._block = LiveBlock(out)
        self._next_s = -math.inf
        self._last: SessionView | None = None

    def note(self, note: Note) -> None:
        if note.closing:  # joyfly's last line on stderr says it
            return
        self._block.erase()
        mark = {Level.WARN: "! ", Level.ERROR: "!! "}.get(note.level, "")
        self.out.write(f"{mark}{note.text}\n")
        if self._last is not None:
            self._block.draw(render(self._last))

    def show(self, view: SessionView) -> None:
        self._last = view
        if view.time_s < self._next_s:
            return
        self._next_s = view.time_s + LIVE_PERIOD_S
        self._block.draw(render(view))

    def close(self, keep: bool = True) -> None:
        """Leave the last view on the terminal, or (keep False: there was nothing to show) take it away."""
        if self._last is not None and keep:
            self._block.draw(render(self._last))
        else:
            self._block.erase()
        self.out.flush()


class PlainLog:
    """For pipes and logs: every note, a status line on each state change, and at most one a second."""

    def __init__(self, out: TextIO) -> None:
        self.out = out
        self._key: tuple[object, ...] | None = None
        self._next_s = -math.inf
        self._t_s = 0.0

    def note(self, note: Note) -> None:
        if note.closing:  # joyfly's last line on stderr says it
            return
        level = {Level.WARN: "WARNING ", Level.ERROR: "ERROR "}.get(note.level, "")
        self.out.write(f"[{self._t_s:7.2f}] {level}{note.text}\n")
        self.out.flush()

    def show(self, view: SessionView) -> None:
        self._t_s = view.time_s
        key = (view.phase, view.mode, view.armed, view.link_ok, view.joystick_ok, view.landed_state)
        flying = view.streaming and view.time_s >= self._next_s
        if key == self._key and not flying:
            return
        self._key = key
        self._next_s = view.time_s + PLAIN_PERIOD_S
        pos = view.pos_ned_m
        margin = _margin(view)
        sp = view.setpoint.pos_ned_m if view.setpoint is not None else None
        sent = f"sent {view.manual.describe()}" if view.manual is not None else f"sp {fmt_vec(sp)}"
        phase = view.phase_text or view.phase.value
        self.out.write(f"[{view.time_s:7.2f}] {phase}; {view.mode} {'armed' if view.armed else 'disarmed'}"
                       f"; link {_link_word(view)}; pos {fmt_vec(pos)} {sent}"
                       f"; fence margin {fmt_margin(margin, view.fence_alert)}\n")
        self.out.flush()

    def close(self, keep: bool = True) -> None:
        self.out.flush()


def make_view(out: TextIO, live: bool | None = None) -> LiveDashboard | PlainLog:
    """The live block on a terminal, plain lines otherwise (`live` forces one or the other)."""
    is_tty = out.isatty() if live is None else live
    return LiveDashboard(out) if is_tty else PlainLog(out)
