"""The flight session: connect, pre-stream setpoints, arm, enter OFFBOARD, stream at a fixed rate, react to
failsafes, land on exit. A state machine on an injected clock, so tests fly it in simulated time.

The order is the one every PX4 offboard client must follow (px4-behaviour.md 4.2; PX4 offboardCheck.cpp): setpoints
stream BEFORE arming and switching, because PX4 refuses OFFBOARD (and arming in OFFBOARD) without a setpoint younger
than COM_OF_LOSS_T = 1 s. Once the vehicle leaves OFFBOARD on its own (failsafe, another GCS), joyfly stops
sending setpoints and waits for the user's OFFBOARD button: PX4 would return to OFFBOARD by itself as soon as
setpoints resume (failsafe.cpp: the fallback clears when the condition clears), which would fight the failsafe.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from enum import Enum
from typing import Protocol

from joyfly.failsafes import JoystickWatch, LinkWatch, Retry
from joyfly.link import MAIN_AUTO, MAIN_OFFBOARD, SUB_AUTO_LOITER, VehicleLink
from joyfly.setpoints import Fence, Limits, Setpoint, hold_setpoint, initial_setpoint, next_setpoint
from joyfly.types import Action, Clock, StickCommand

log = logging.getLogger(__name__)


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
    min_alt_m: float = 0.5
    max_alt_m: float = 10.0
    limits: Limits = field(default_factory=Limits)


@dataclass(frozen=True, slots=True)
class Note:
    time_s: float
    level: str  # info | warn | error
    text: str


@dataclass(frozen=True, slots=True)
class FlightStats:
    distance_m: float = 0.0
    min_fence_margin_m: float = math.inf
    offboard_time_s: float = 0.0
    max_alt_m: float = 0.0


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


class FlightSession:
    """Run with `run()`; `request_exit()` (e.g. from SIGINT) performs the --on-exit action and finishes."""

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
        self._start_s = clock.now()
        self._phase_s = self._start_s
        self._period_s = 1.0 / max(settings.rate_hz, 1.0)
        self._last_sp_s = self._start_s
        self._last_tick_s = self._start_s
        self._prestreamed = 0
        self._retry: Retry | None = None
        self._joy = JoystickWatch(settings.joy_timeout_s)
        self._linkw = LinkWatch()
        self._prev_pressed: frozenset[Action] = frozenset()
        self._arm_fired = False
        self._last_pos: tuple[float, float, float] | None = None
        self.setpoints_sent = 0
        self.on_setpoint: list[Callable[[Setpoint], None]] = []
        self._exit_done: Callable[[], bool] = lambda: True
        self._exit_action: Callable[[], object] = lambda: None

    # --- the loop ----------------------------------------------------------------------------------------------
    @property
    def finished(self) -> bool:
        return self.phase in (Phase.DONE, Phase.FAILED)

    def run(self, on_view: Callable[[SessionView], None] | None = None) -> None:
        next_tick = self.clock.now()
        while not self.finished:
            if self.clock.now() >= next_tick - 1e-6:
                self.tick()
                if on_view is not None:
                    on_view(self.view())
                next_tick = max(next_tick + self._period_s, self.clock.now() - self._period_s)
            self._wait_sticks(next_tick)

    def _wait_sticks(self, next_tick: float) -> None:
        """Read the sticks until the next tick; a changed stick is sent at once (low latency)."""
        remaining = next_tick - self.clock.now()
        cmd = self.sticks.poll(max(0.0, remaining))
        changed = replace(cmd, time_s=0.0) != replace(self.cmd, time_s=0.0)
        self.cmd = cmd
        if changed and self.phase is Phase.FLYING and self._streaming_allowed():
            self._send_flight_setpoint()
            return
        remaining = next_tick - self.clock.now()
        if remaining > 1e-6 and not changed:
            self.clock.sleep(remaining)

    def tick(self) -> None:
        """One period: read telemetry, run the watchdogs and the phase, stream a setpoint if the phase does."""
        now = self.clock.now()
        self.link.poll(0.0)
        self.link.tick()
        for text in self.link.take_new_statustexts():
            self._note("warn" if text.severity <= 4 else "info", f"Vehicle: {text.text}")
        self._update_stats(now)
        if self.exit_requested and self.phase not in (Phase.EXITING, Phase.DONE, Phase.FAILED):
            self._begin_exit()
        if self.phase is not Phase.CONNECTING and not self._watch_link(now):
            self._tick_exit_timeout(now)
            return
        self._watch_joystick(now)
        if self.phase not in (Phase.EXITING, Phase.CONNECTING):
            self._handle_buttons()
        _PHASE_HANDLERS[self.phase](self, now)
        self._last_tick_s = now

    def request_exit(self) -> None:
        self.exit_requested = True

    # --- helpers -------------------------------------------------------------------------------------------------
    def _note(self, level: str, text: str) -> None:
        note = Note(self.clock.now(), level, text)
        self.notes.append(note)
        del self.notes[:-20]
        getattr(log, {"info": "info", "warn": "warning"}.get(level, "error"))(text)
        if self.on_note is not None:
            self.on_note(note)

    def _set_phase(self, phase: Phase) -> None:
        if phase is not self.phase:
            log.debug("phase %s -> %s", self.phase.name, phase.name)
            self.phase = phase
            self._phase_s = self.clock.now()
            self._retry = None

    def _fail(self, text: str) -> None:
        self.error = text
        self._note("error", text)
        self._set_phase(Phase.FAILED)

    def _streaming_allowed(self) -> bool:
        return self.phase in STREAMING_PHASES and self._linkw.ok

    def _send(self, sp: Setpoint) -> None:
        self.sp = sp
        self._last_sp_s = self.clock.now()
        self.link.send_setpoint(sp)
        self.setpoints_sent += 1
        for observer in self.on_setpoint:
            observer(sp)

    def _vehicle_pos(self) -> tuple[float, float, float]:
        pos = self.link.state.pos_ned_m
        return pos if pos is not None else (0.0, 0.0, 0.0)

    def _hold_here(self) -> Setpoint:
        return hold_setpoint(self._vehicle_pos(), self.link.state.yaw_rad, self.fence)

    def _send_flight_setpoint(self) -> None:
        now = self.clock.now()
        assert self.sp is not None
        if self._joy.holding or self.cmd.deadman_ok is False:
            sp = replace(self.sp, vel_ned_m_s=(0.0, 0.0, 0.0) if self.sp.vel_ned_m_s is not None else None)
        else:
            dt = min(max(now - self._last_sp_s, 0.0), 0.2)
            sp = next_setpoint(self.sp, self.cmd, self._vehicle_pos(), dt, self.s.limits, self.fence)
        self._send(sp)

    # --- watchdogs -------------------------------------------------------------------------------------------
    def _watch_link(self, now: float) -> bool:
        change = self._linkw.update(self.link.state.link_ok(now))
        if change == "lost":
            self._note("warn", f"Link lost: no HEARTBEAT from the vehicle for 3 s; still trying on "
                               f"{self.link.transport.description}.")
        elif change == "back":
            self._note("info", "Link back: the vehicle answers again.")
            self._on_link_back()
        return self._linkw.ok

    def _on_link_back(self) -> None:
        st = self.link.state
        if self.phase in STREAMING_PHASES:
            if not st.armed:
                self._set_phase(Phase.GROUNDED)
            elif st.offboard:
                self.sp = self._hold_here()
            else:
                self.sp = self._hold_here()
                self._set_phase(Phase.RESUMING)

    def _watch_joystick(self, now: float) -> None:
        change = self._joy.update(self.cmd.connected, now)
        if change == "lost":
            self._note("warn", f"Joystick lost: holding position; landing in {self.s.joy_timeout_s:g} s "
                               "unless it comes back.")
            if self.phase is Phase.FLYING:
                self.sp = self._hold_here()
        elif change == "back":
            self._note("info", "Joystick back: you have control again.")
        if self._joy.expired(now) and self.phase is Phase.FLYING:
            self._note("warn", f"Joystick still lost after {self.s.joy_timeout_s:g} s: landing.")
            self.link.land()
            self._set_phase(Phase.LANDING)

    def _update_stats(self, now: float) -> None:
        st = self.link.state
        dt = now - self._last_tick_s
        pos = st.pos_ned_m
        if pos is None or not st.armed:
            self._last_pos = pos
            return
        s = self.stats
        dist = s.distance_m
        if self._last_pos is not None:
            dist += math.dist(pos, self._last_pos)
        self._last_pos = pos
        margin = min(s.min_fence_margin_m, self.fence.margin_m(pos)) if st.landed_state != 1 else s.min_fence_margin_m
        self.stats = FlightStats(dist, margin, s.offboard_time_s + (dt if st.offboard else 0.0),
                                 max(s.max_alt_m, self.fence.alt_m(pos)))

    # --- buttons -----------------------------------------------------------------------------------------------
    def _handle_buttons(self) -> None:
        pressed = self.cmd.pressed
        new = pressed - self._prev_pressed
        self._prev_pressed = pressed
        held = dict(self.cmd.held_s)
        if Action.ARM not in pressed:
            self._arm_fired = False
        elif held.get(Action.ARM, 0.0) >= 1.0 and not self._arm_fired:
            self._arm_fired = True
            new = new | {Action.ARM}
        for action in (Action.LAND, Action.RETURN, Action.HOLD, Action.OFFBOARD, Action.TAKEOFF, Action.ARM):
            if action in new:
                self._on_button(action)

    def _on_button(self, action: Action) -> None:
        st = self.link.state
        if action is Action.LAND and st.armed:
            self._note("info", "LAND pressed: landing.")
            self.link.land()
            self._set_phase(Phase.LANDING)
        elif action is Action.RETURN and st.armed:
            self._note("info", "RETURN pressed: returning to launch.")
            self.link.return_to_launch()
            self._set_phase(Phase.LANDING)
        elif action is Action.HOLD and st.armed:
            self._note("info", "HOLD pressed: the vehicle holds in AUTO.LOITER; press OFFBOARD to fly again.")
            self.link.set_mode(MAIN_AUTO, SUB_AUTO_LOITER)
            self._set_phase(Phase.PAUSED)
        elif action is Action.ARM and st.armed and st.on_ground:
            self._note("info", "ARM held: disarming.")
            self.link.arm(False)
        elif action in (Action.OFFBOARD, Action.TAKEOFF, Action.ARM) and self.phase in (
                Phase.PAUSED, Phase.GROUNDED, Phase.LANDING):
            self._start_control(f"{action.value.upper()} pressed")

    def _start_control(self, why: str) -> None:
        st = self.link.state
        if st.armed and not st.on_ground:
            self._note("info", f"{why}: taking control at the current position.")
            self.sp = self._hold_here()
        else:
            self._note("info", f"{why}: taking off to {self.s.alt_m:g} m.")
            self._reset_home()
            self.sp = initial_setpoint(self._vehicle_pos(), st.yaw_rad, self.fence, self.s.alt_m)
        self._prestreamed = 0
        self._set_phase(Phase.PRESTREAM)

    def _reset_home(self) -> None:
        st = self.link.state
        home = st.home_ned_m if st.home_ned_m is not None and not st.armed else self._vehicle_pos()
        self.fence = replace(self.fence, home_ned_m=home)

    # --- phases --------------------------------------------------------------------------------------------------
    def _connecting(self, now: float) -> None:
        st = self.link.state
        if st.link_ok(now) and st.pos_ned_m is not None:
            self._linkw.update(True)
            self._on_connected()
        elif now - self._start_s > self.s.connect_timeout_s:
            self._fail(self._no_vehicle_message())

    def _no_vehicle_message(self) -> str:
        where = self.link.transport.description
        if self.link.state.last_heartbeat_s is not None:
            return (f"The vehicle on {where} sends HEARTBEATs but no LOCAL_POSITION_NED after "
                    f"{self.s.connect_timeout_s:g} s: it has no position estimate yet; wait for it, then retry.")
        return (f"No HEARTBEAT from a vehicle on {where} after {self.s.connect_timeout_s:g} s: start "
                "`sitl-emu serve` or PX4 SITL first (PX4 sends to UDP port 14540), or fix --url.")

    def _on_connected(self) -> None:
        st = self.link.state
        self._note("info", f"Connected to vehicle {st.sysid} on {self.link.transport.description} ({st.mode}, "
                           f"{'armed' if st.armed else 'disarmed'}).")
        self.link.request_home()
        if self.exit_requested:
            self._set_phase(Phase.DONE)
        elif st.armed and st.offboard:
            self._note("info", "The vehicle is already in OFFBOARD: taking over at its position.")
            self.sp = self._hold_here()
            self._set_phase(Phase.FLYING)
        elif st.armed and not st.on_ground:
            self._note("warn", f"The vehicle is already flying in {st.mode}: press OFFBOARD to take control.")
            self._set_phase(Phase.PAUSED)
        else:
            self._start_control("Start")

    def _prestream(self, now: float) -> None:
        assert self.sp is not None
        self._send(self.sp)
        self._prestreamed += 1
        if self._prestreamed >= self.s.prestream_count:
            self._set_phase(Phase.ENTERING if self.link.state.armed else Phase.ARMING)

    def _arming(self, now: float) -> None:
        assert self.sp is not None
        self._send(self.sp)
        if self.link.state.armed:
            self._note("info", "Armed.")
            self._set_phase(Phase.ENTERING)
            return
        if self._retry is None:
            self._retry = Retry("Arming", self.s.arm_attempts, now)
        outcome = self._retry.update(now, self.link, self.link.arm, lambda: self.link.state.armed)
        self._report_retry(outcome)

    def _entering(self, now: float) -> None:
        assert self.sp is not None
        self._send(self.sp)
        st = self.link.state
        if st.offboard and st.armed:
            self._note("info", "OFFBOARD: you have control.")
            self._set_phase(Phase.FLYING)
            return
        if not st.armed and now - self._phase_s > 1.0:
            self._note("warn", "The vehicle disarmed before OFFBOARD was entered.")
            self._set_phase(Phase.GROUNDED)
            return
        if self._retry is None:
            self._retry = Retry("Switching to OFFBOARD", self.s.arm_attempts, now)
        outcome = self._retry.update(now, self.link, lambda: self.link.set_mode(MAIN_OFFBOARD),
                                     lambda: self.link.state.offboard)
        self._report_retry(outcome)

    def _report_retry(self, outcome: str | None) -> None:
        if outcome is None or self._retry is None:
            return
        if outcome == "refused":
            self._note("warn", self._retry.last_refusal)
        elif outcome == "failed":
            if self.link.state.on_ground and self.link.state.armed:
                self.link.arm(False)
            self._fail(self._retry.failure_message())

    def _resuming(self, now: float) -> None:
        assert self.sp is not None
        self._send(self.sp)
        if self.link.state.offboard:
            self._note("info", "The vehicle is back in OFFBOARD: you have control.")
            self._set_phase(Phase.FLYING)
        elif now - self._phase_s > 2.0:
            self._note("warn", f"The vehicle stays in {self.link.state.mode}: press OFFBOARD to take control.")
            self._set_phase(Phase.PAUSED)

    def _flying(self, now: float) -> None:
        st = self.link.state
        if not st.offboard:
            self._note("warn", self._left_offboard_message())
            self._set_phase(Phase.PAUSED if st.armed else Phase.GROUNDED)
            return
        self._send_flight_setpoint()

    def _left_offboard_message(self) -> str:
        st = self.link.state
        recent = [t.text for t in self.link.statustexts if self.clock.now() - t.time_s < 3.0]
        why = f" ({recent[-1]})" if recent else ""
        return (f"The vehicle left OFFBOARD for {st.mode}{why}: joyfly stopped sending setpoints and will not "
                "fight it; press OFFBOARD to take control again.")

    def _paused(self, now: float) -> None:
        st = self.link.state
        if not st.armed:
            self._note("info", "The vehicle is on the ground and disarmed.")
            self._set_phase(Phase.GROUNDED)

    def _landing(self, now: float) -> None:
        if not self.link.state.armed:
            self._note("info", "Landed and disarmed.")
            self._set_phase(Phase.GROUNDED)

    def _grounded(self, now: float) -> None:
        if self.s.exit_when_landed:
            self._set_phase(Phase.DONE)

    # --- exit ----------------------------------------------------------------------------------------------------
    def _begin_exit(self) -> None:
        st = self.link.state
        if self.phase is Phase.CONNECTING or not st.armed:
            self._set_phase(Phase.DONE)
            return
        self._note("info", f"Exiting: {self.s.on_exit} (press Ctrl-C again to quit at once).")
        self._set_phase(Phase.EXITING)

    def _exiting(self, now: float) -> None:
        st = self.link.state
        on_exit = self.s.on_exit
        if self._retry is None:
            action = {"land": self.link.land, "rtl": self.link.return_to_launch}.get(
                on_exit, lambda: self.link.set_mode(MAIN_AUTO, SUB_AUTO_LOITER))
            done = (lambda: not self.link.state.offboard) if on_exit == "hold" else (lambda: not self.link.state.armed)
            self._retry = Retry(f"Exit action {on_exit}", 3, now, settle_s=self.s.exit_timeout_s)
            self._exit_done = done
            self._exit_action = action
        if st.offboard and self.sp is not None:
            self._send(replace(self.sp, vel_ned_m_s=(0.0, 0.0, 0.0) if self.sp.vel_ned_m_s else None))
        if self._exit_done():
            self._note("info", "Landed and disarmed." if on_exit != "hold" else "The vehicle holds position.")
            self._set_phase(Phase.DONE)
            return
        outcome = self._retry.update(now, self.link, self._exit_action, lambda: False)
        if outcome == "refused":
            self._note("warn", self._retry.last_refusal)
        self._tick_exit_timeout(now)

    def _tick_exit_timeout(self, now: float) -> None:
        if self.phase is Phase.EXITING and now - self._phase_s > self.s.exit_timeout_s:
            self._note("error", f"The vehicle did not finish '{self.s.on_exit}' within {self.s.exit_timeout_s:g} s; "
                                "it may still be armed: take over with a ground station.")
            self._set_phase(Phase.DONE)

    # --- view ------------------------------------------------------------------------------------------------
    def view(self) -> SessionView:
        st = self.link.state
        now = self.clock.now()
        return SessionView(
            time_s=now - self._start_s, phase=self.phase, link_ok=st.link_ok(now), mode=st.mode, armed=st.armed,
            landed_state=st.landed_state, pos_ned_m=st.pos_ned_m, setpoint=self.sp,
            streaming=self._streaming_allowed(), stick=self.cmd, joystick_ok=not self._joy.holding,
            fence=self.fence, stats=self.stats, statustexts=tuple(t.text for t in list(self.link.statustexts)[-5:]),
            notes=tuple(self.notes[-5:]), link_description=self.link.transport.description)


_PHASE_HANDLERS: dict[Phase, Callable[[FlightSession, float], None]] = {
    Phase.CONNECTING: FlightSession._connecting,
    Phase.PRESTREAM: FlightSession._prestream,
    Phase.ARMING: FlightSession._arming,
    Phase.ENTERING: FlightSession._entering,
    Phase.RESUMING: FlightSession._resuming,
    Phase.FLYING: FlightSession._flying,
    Phase.PAUSED: FlightSession._paused,
    Phase.LANDING: FlightSession._landing,
    Phase.GROUNDED: FlightSession._grounded,
    Phase.EXITING: FlightSession._exiting,
    Phase.DONE: lambda self, now: None,
    Phase.FAILED: lambda self, now: None,
}
