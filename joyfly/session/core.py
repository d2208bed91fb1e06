"""The flight session's vocabulary and state: phases, settings, notes to the user, flight statistics, the view
snapshot the live view draws, and `SessionCore`, the session's state with its small helpers. The behaviour (loop,
watchdogs, buttons, phases) is `FlightSession` in joyfly/session/flight_session.py."""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from enum import Enum
from typing import Protocol

from joyfly.link.vehicle_link import VehicleLink, VehicleState
from joyfly.session.fence_watch import FenceWatch, breach_alert
from joyfly.session.retry import ExitPlan, Retry
from joyfly.session.watchdogs import JoystickWatch, LinkWatch
from joyfly.sticks.manual import ManualInput
from joyfly.sticks.setpoints import Fence, Limits, Setpoint, hold_setpoint
from joyfly.types import Action, Clock, StickCommand

log = logging.getLogger("joyfly.session.flight_session")

MIN_SEND_GAP_S = 0.01  # stick changes are sent at once, at most 100 times a second (plus the stream's ticks)
STALE_S = 0.5  # the vehicle's state is news while it keeps sending (PX4's ATTITUDE: 15-100 Hz); older is a guess


class Phase(Enum):
    CONNECTING = "connecting"
    PRESTREAM = "pre-streaming setpoints"
    ARMING = "arming"
    ENTERING = "entering OFFBOARD"
    RESUMING = "resuming the setpoint stream"
    FLYING = "flying in OFFBOARD"
    PAUSED = "not commanding"
    LANDING = "landing"
    GROUNDED = "landed"
    EXITING = "exiting"
    DONE = "done"
    FAILED = "failed"


STREAMING_PHASES = (Phase.PRESTREAM, Phase.ARMING, Phase.ENTERING, Phase.RESUMING, Phase.FLYING)


class StickSource(Protocol):
    """Normalised stick commands (the joystick side's mapping output), read without blocking longer than asked."""

    def poll(self, timeout_s: float) -> StickCommand: ...

    def close(self) -> None: ...


@dataclass(frozen=True, slots=True)
class SessionSettings:
    alt_m: float = 3.0
    rate_hz: float = 20.0
    on_exit: str = "land"  # land | hold | rtl
    joy_timeout_s: float = 5.0
    connect_timeout_s: float = 15.0
    prestream_count: int = 10  # setpoints sent before arming (the seed node sends its first ones the same way)
    arm_attempts: int = 3
    exit_timeout_s: float = 60.0
    exit_when_landed: bool = False  # `joyfly demo`: finish once the vehicle has landed and disarmed
    fence_m: float = 5.0
    fence_action: str = "land"  # warn | hold | rtl | land: when the vehicle stays outside the fence (fence_watch.py)
    min_alt_m: float = 0.5
    max_alt_m: float = 10.0
    limits: Limits = field(default_factory=Limits)


class Level(Enum):
    """How much a note matters: the dashboard marks warnings and errors, and the log gets the same level."""

    INFO = logging.INFO
    WARN = logging.WARNING
    ERROR = logging.ERROR


@dataclass(frozen=True, slots=True)
class Note:
    """One thing joyfly tells the pilot (the face prints it above the live view), stamped with the session's clock."""

    time_s: float
    level: Level
    text: str
    closing: bool = False  # the session's failure: joyfly ends with this sentence on stderr, the terminal prints none


@dataclass(frozen=True, slots=True)
class FlightStats:
    """What the closing summary says of the flight, counted as it goes."""

    distance_m: float = 0.0
    min_fence_margin_m: float = math.inf
    control_time_s: float = 0.0  # time in joyfly's mode: OFFBOARD, or POSCTL/ALTCTL with --control position/altitude
    max_alt_m: float = 0.0
    fence_breaches: int = 0  # times the vehicle went outside the fence (further than FENCE_TOLERANCE_M)
    deepest_breach_m: float = 0.0  # the furthest outside it went


@dataclass(frozen=True, slots=True)
class SessionView:
    """Everything the live view shows, one consistent snapshot."""

    time_s: float
    phase: Phase
    link_ok: bool
    mode: str
    armed: bool
    landed_state: int
    pos_ned_m: tuple[float, float, float] | None
    setpoint: Setpoint | None
    streaming: bool
    stick: StickCommand
    joystick_ok: bool
    fence: Fence
    stats: FlightStats
    statustexts: tuple[str, ...]
    notes: tuple[Note, ...]
    link_description: str
    heard: bool = True  # a vehicle has answered
    control: str = "OFFBOARD"  # the mode joyfly flies in
    manual: ManualInput | None = None  # the last MANUAL_CONTROL sent (--control position/altitude), else None
    phase_text: str = ""  # the phase in words for this way of flying ("" = phase.value)
    fence_alert: str = ""  # the breach under way and what joyfly will do about it ("" = none)
    home_known: bool = True  # False until joyfly knows this flight's home (after a restart: the old one is void)


def update_stats(stats: FlightStats, prev_pos: tuple[float, float, float] | None, st: VehicleState, fence: Fence,
                 dt_s: float, now_s: float, in_control: bool | None = None) -> FlightStats:
    """Accumulate distance flown, closest approach to the fence (in the air) and time in joyfly's mode (`in_control`,
    OFFBOARD by default), while armed and while the vehicle is heard (a link outage is not time in OFFBOARD: we do
    not know what it did)."""
    pos = st.pos_ned_m
    if pos is None or not st.armed or st.stamped_s is None or now_s - st.stamped_s > STALE_S:
        return stats
    dist = stats.distance_m + (math.dist(pos, prev_pos) if prev_pos is not None else 0.0)
    in_air = st.landed_state != 1
    margin = min(stats.min_fence_margin_m, fence.margin_m(pos)) if in_air else stats.min_fence_margin_m
    controlled = st.offboard if in_control is None else in_control
    control_time = stats.control_time_s + (dt_s if controlled else 0.0)
    return replace(stats, distance_m=dist, min_fence_margin_m=margin, control_time_s=control_time,
                   max_alt_m=max(stats.max_alt_m, fence.alt_m(pos)))


def no_vehicle_message(where: str, heard: bool, timeout_s: float, port_taken: bool | None = None) -> str:
    """Why the session could not start, and what to do about it; `port_taken`: a program on this machine holds the
    port the vehicle should answer from (the transport's vehicle_port_taken)."""
    if not heard and port_taken:
        return (f"No HEARTBEAT on {where} after {timeout_s:g} s, though a program holds that vehicle port on this "
                "machine: the vehicle is probably busy with another client (PX4's API link, as sitl-emu serve's, "
                "answers only the first client it hears, for good); quit that client and start joyfly on its port, "
                "or restart the vehicle.")
    if heard:
        return (f"The vehicle on {where} sends HEARTBEATs but no LOCAL_POSITION_NED after {timeout_s:g} s: it has "
                "no position estimate yet; wait for it, then retry.")
    return (f"No HEARTBEAT from a vehicle on {where} after {timeout_s:g} s: start `sitl-emu serve` or PX4 SITL "
            "first (PX4 sends to UDP port 14540), or fix --url.")


def restarted_message(st: VehicleState, quitting: bool) -> str:
    """What a restart of the vehicle means for the user (its boot time went back)."""
    before = f"{st.uptime_before_restart_s:.1f} s" if st.uptime_before_restart_s is not None else "?"
    now = f"{st.boot_s:.1f} s" if st.boot_s is not None else "?"
    then = "joyfly quits." if quitting else "press ARM or TAKEOFF to fly again, or Ctrl-C to quit."
    return (f"The vehicle restarted (its time since boot went back from {before} to {now}): this flight is over. "
            f"A restarted PX4 is disarmed; joyfly stopped sending setpoints and will not arm it again on its own: "
            f"{then}")


def left_offboard_message(mode: str, recent_texts: list[str]) -> str:
    why = f" ({recent_texts[-1]})" if recent_texts else ""
    return (f"The vehicle left OFFBOARD for {mode}{why}: joyfly stopped sending setpoints and will not fight it; "
            "press OFFBOARD to take control again.")


class SessionCore:
    """The flight session's state and helpers (notes, phase changes, sending, the view)."""

    def __init__(self, link: VehicleLink, sticks: StickSource, clock: Clock, settings: SessionSettings,
                 on_note: Callable[[Note], None] | None = None) -> None:
        self.link, self.sticks, self.clock, self.s = link, sticks, clock, settings
        self.on_note = on_note
        self.phase = Phase.CONNECTING
        self.fence = Fence((0.0, 0.0, 0.0), settings.fence_m, settings.min_alt_m, settings.max_alt_m)
        self.sp: Setpoint | None = None
        self.cmd = StickCommand()
        self.stats = FlightStats()
        self.notes: list[Note] = []
        self.exit_requested = False
        self.error: str | None = None
        self.error_is_mistake = False  # the failure is the user's to fix (the joystick sends no js_events): exit 2
        self._start_s = clock.now()
        self._phase_s = self._start_s
        self._period_s = 1.0 / max(settings.rate_hz, 1.0)
        self._last_sp_s = self._start_s
        self._last_tick_s = self._start_s
        self._prestreamed = 0
        self._retry: Retry | None = None
        self._joy = JoystickWatch(settings.joy_timeout_s)
        self._linkw = LinkWatch()
        self._fired: frozenset[Action] = frozenset()
        self._arm_hold_s = float(getattr(getattr(sticks, "profile", None), "arm_hold_s", 1.0))
        self._last_pos: tuple[float, float, float] | None = None
        self.setpoints_sent = 0
        self.manual_sent: ManualInput | None = None  # the last MANUAL_CONTROL (ManualSession)
        self.on_setpoint: list[Callable[[Setpoint], None]] = []
        self._exit: ExitPlan | None = None
        self._dirty = False  # the sticks changed since the last setpoint was sent
        self._next_tick_s = self._start_s
        self._last_immediate_s = -MIN_SEND_GAP_S
        self._hold_requests = 0
        self._hold_sent_s = -math.inf
        self.armed_seen = False  # the vehicle was armed at some point of this session: there is a flight to sum up
        self._restarts_seen = 0
        self._restart_s = -math.inf  # when joyfly last reported a restart of the vehicle
        self._link_note_s = -math.inf  # when joyfly last said the link is lost (LINK_REMINDER_S apart)
        self._home_from_vehicle = False  # True when joyfly took over a flying vehicle: its HOME_POSITION is home
        self.home_known = False  # the fence's home is this flight's (set where joyfly arms, or the vehicle's own)
        self.fence_watch = FenceWatch()
        self.airborne_mode: str | None = None  # the vehicle's mode while last known armed in the air, else None
        self.unlanded: str | None = None  # why a flight of this session ended in the air (the vehicle restarted)

    def in_control(self, st: VehicleState) -> bool:
        """Whether the vehicle is in the mode joyfly flies it in (OFFBOARD here; ManualSession: POSCTL/ALTCTL)."""
        return st.offboard

    def control_label(self) -> str:
        """The mode joyfly flies in, as the live view and the summary name it."""
        return "OFFBOARD"

    def phase_text(self) -> str:
        return self.phase.value

    def summary_extra(self) -> list[str]:
        """Lines the flight's summary adds for this way of flying."""
        return []

    def landing_missing(self) -> str | None:
        """Why a flight of this session ended without a landing, or None: the vehicle restarted in the air, or
        joyfly ends with the vehicle last known armed in the air (unless the user asked --on-exit hold)."""
        if self.unlanded is not None:
            return self.unlanded
        if self.airborne_mode is None or (self.exit_requested and self.s.on_exit == "hold"):
            return None
        heard = "" if self.link.state.link_ok(self.clock.now()) else " (the link is lost: as last heard)"
        return f"joyfly ends with the vehicle armed in the air in {self.airborne_mode}{heard}"

    @property
    def finished(self) -> bool:
        return self.phase in (Phase.DONE, Phase.FAILED)

    @property
    def exit_mode(self) -> str | None:
        """The mode the vehicle accepted for --on-exit (AUTO.LAND...), None before it did."""
        return self._exit.commanded_mode if self._exit is not None else None

    def request_exit(self) -> None:
        """Perform --on-exit, then finish (the first Ctrl-C)."""
        self.exit_requested = True

    def abort(self) -> None:
        """Finish at once: no exit action, the vehicle keeps its mode (and PX4's offboard-loss failsafe acts)."""
        self._set_phase(Phase.DONE)

    def _note(self, level: Level, text: str, closing: bool = False) -> None:
        note = Note(self.clock.now(), level, text, closing)
        self.notes.append(note)
        del self.notes[:-20]
        log.log(level.value, text)
        if self.on_note is not None:
            self.on_note(note)

    def _set_phase(self, phase: Phase) -> None:
        if phase is not self.phase:
            log.debug("phase %s -> %s", self.phase.name, phase.name)
            self.phase = phase
            self._phase_s = self.clock.now()
            self._retry = None

    def _fail(self, text: str, mistake: bool = False) -> None:
        self.error, self.error_is_mistake = text, mistake
        self._note(Level.ERROR, text, closing=True)
        self._set_phase(Phase.FAILED)

    def _streaming_allowed(self) -> bool:
        return self.phase in STREAMING_PHASES and self._linkw.ok

    def _send(self, sp: Setpoint) -> None:
        self.sp = sp
        self._dirty = False
        self._last_sp_s = self.clock.now()
        self.link.send_setpoint(sp)
        self.setpoints_sent += 1
        for observer in self.on_setpoint:
            observer(sp)

    def _vehicle_pos(self) -> tuple[float, float, float]:
        pos = self.link.state.pos_ned_m
        return pos if pos is not None else (0.0, 0.0, 0.0)

    def _hold_here(self) -> Setpoint:
        st = self.link.state
        return hold_setpoint(self._vehicle_pos(), st.yaw_rad, self.fence, st.vel_ned_m_s, self.s.limits.lag_s)

    def _update_stats(self, now: float) -> None:
        st = self.link.state
        self.stats = update_stats(self.stats, self._last_pos, st, self.fence, now - self._last_tick_s, now,
                                  self.in_control(st))
        self._last_pos = st.pos_ned_m

    def _note_once(self, text: str) -> None:
        if not any(n.text == text for n in self.notes):
            self._note(Level.INFO, text)

    def view(self) -> SessionView:
        st = self.link.state
        now = self.clock.now()
        return SessionView(
            time_s=now - self._start_s, phase=self.phase, link_ok=st.link_ok(now), mode=st.mode, armed=st.armed,
            landed_state=st.landed_state, pos_ned_m=st.pos_ned_m, setpoint=self.sp,
            streaming=self._streaming_allowed(), stick=self.cmd, joystick_ok=not self._joy.lost,
            fence=self.fence, stats=self.stats, statustexts=tuple(t.text for t in list(self.link.statustexts)[-5:]),
            notes=tuple(self.notes[-5:]), link_description=self.link.transport.description,
            heard=st.last_heartbeat_s is not None, control=self.control_label(), manual=self.manual_sent,
            phase_text=self.phase_text(), home_known=self.home_known,
            fence_alert=breach_alert(self.fence_watch, self.s.fence_action, self.phase is Phase.FLYING, now))
