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
from collections.abc import Callable
from dataclasses import replace

from joyfly.link.vehicle_link import MAIN_AUTO, MAIN_OFFBOARD, SUB_AUTO_LOITER
from joyfly.session.core import (
    MIN_SEND_GAP_S,
    FlightStats,
    Note,
    Phase,
    SessionSettings,
    SessionView,
    StickSource,
    left_offboard_message,
    no_vehicle_message,
)
from joyfly.session.retry import ExitPlan, Retry
from joyfly.session.watch import SessionWatch
from joyfly.sticks.mapping import fired
from joyfly.sticks.setpoints import initial_setpoint, next_setpoint
from joyfly.types import Action

__all__ = ["FlightSession", "FlightStats", "Note", "Phase", "SessionSettings", "SessionView", "StickSource"]

MAV_STATE_STANDBY = 3  # HEARTBEAT.system_status once PX4's arming checks pass (px4-behaviour.md 2.4)
READY_WAIT_S = 10.0  # then try to arm anyway, so the vehicle's refusal explains what is missing
# Arm only in Hold or OFFBOARD: PX4 refuses to arm in Return, Land, Descend... (mode_req_prevent_arming,
# ModeUtil/mode_requirements.cpp) and in the manual modes without RC (px4-behaviour.md 3.2)
ARMABLE_MODES = ("AUTO.LOITER", "OFFBOARD")

log = logging.getLogger(__name__)


class FlightSession(SessionWatch):
    """Run with `run()`; `request_exit()` (e.g. from SIGINT) performs the --on-exit action and finishes."""

    # --- the loop ----------------------------------------------------------------------------------------------

    def run(self, on_view: Callable[[SessionView], None] | None = None) -> None:
        """Fly until done (or failed): a tick every 1/rate s, the sticks read in between."""
        while not self.finished:
            self.run_once(on_view)

    def run_once(self, on_view: Callable[[SessionView], None] | None = None) -> None:
        """One loop iteration: the tick if it is due, then read the sticks until the next one."""
        if self.clock.now() >= self._next_tick_s - 1e-6:
            self.tick()
            if on_view is not None:
                on_view(self.view())
            self._next_tick_s = max(self._next_tick_s + self._period_s, self.clock.now() - self._period_s)
        self._wait_sticks(self._next_tick_s)

    def _wait_sticks(self, next_tick: float) -> None:
        """Read the sticks until the next tick; a changed stick is sent at once (low latency), such extra sends at
        most every MIN_SEND_GAP_S (a jittery axis must not flood the link)."""
        wait = max(0.0, next_tick - self.clock.now())
        if self._send_now_possible():
            wait = min(wait, max(0.0, self._last_immediate_s + MIN_SEND_GAP_S - self.clock.now()))
        # a device waits in wall seconds, a script on our clock: ask for wall time, sleep the rest on our clock
        cmd = self.sticks.poll(wait / getattr(self.clock, "speed", 1.0))
        self._dirty |= replace(cmd, time_s=0.0) != replace(self.cmd, time_s=0.0)
        self._fired |= fired(self.cmd, cmd, self._arm_hold_s)
        self.cmd = cmd
        now = self.clock.now()
        if self._send_now_possible():
            gap = self._last_immediate_s + MIN_SEND_GAP_S - now
            if gap <= 0:
                self._last_immediate_s = now
                self._send_flight_setpoint()
                return
            wait = min(gap, next_tick - now)
        else:
            wait = next_tick - now
        if wait > 1e-6:
            self.clock.sleep(wait)

    def _send_now_possible(self) -> bool:
        return self._dirty and self.phase is Phase.FLYING and self._streaming_allowed()

    def tick(self) -> None:
        """One period: read telemetry, run the watchdogs and the phase, stream a setpoint if the phase does."""
        now = self.clock.now()
        self.link.poll(0.0)
        self.link.tick()
        for text in self.link.take_new_statustexts():
            self._note("warn" if text.severity <= 4 else "info", f"Vehicle: {text.text}")
        self._update_stats(now)
        self._last_tick_s = now
        if self.exit_requested and self.phase not in (Phase.EXITING, Phase.DONE, Phase.FAILED):
            self._begin_exit()
        if self.phase is not Phase.CONNECTING:
            self._watch_vehicle(now)
            if not self._watch_link(now):
                self._tick_exit_timeout(now)
                return
        self._watch_joystick(now)
        if self.phase not in (Phase.EXITING, Phase.CONNECTING):
            self._handle_buttons()
        _PHASE_HANDLERS[self.phase](self, now)

    # --- helpers -------------------------------------------------------------------------------------------------

    def _send_flight_setpoint(self) -> None:
        now = self.clock.now()
        assert self.sp is not None
        if self._joy.lost or self.cmd.deadman_ok is False:
            sp = replace(self.sp, vel_ned_m_s=(0.0, 0.0, 0.0) if self.sp.vel_ned_m_s is not None else None)
        else:
            dt = min(max(now - self._last_sp_s, 0.0), 0.2)
            sp = next_setpoint(self.sp, self.cmd, self._vehicle_pos(), dt, self.s.limits, self.fence,
                               self.link.state.vel_ned_m_s)
        self._send(sp)

    # --- buttons -----------------------------------------------------------------------------------------------

    def _handle_buttons(self) -> None:
        """Act on the buttons that fired since the last tick (ARM after its hold, the others on the press)."""
        new, self._fired = self._fired, frozenset()
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
        elif action is Action.ARM and st.armed and st.on_ground and self.phase in (Phase.PAUSED, Phase.GROUNDED):
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
            self._home_here()
            self.sp = initial_setpoint(self._vehicle_pos(), st.yaw_rad, self.fence, self.s.alt_m)
        self._prestreamed = 0
        self._hold_requests = 0
        self._set_phase(Phase.PRESTREAM)

    def _home_here(self) -> None:
        """Centre the fence (and measure altitudes from) where joyfly arms the vehicle: PX4 sets its home there when
        it arms (COM_HOME_EN, Commander::arm), so a HOME_POSITION read before arming is the last flight's home."""
        self._home_from_vehicle = False
        self.fence = replace(self.fence, home_ned_m=self._vehicle_pos())

    # --- phases --------------------------------------------------------------------------------------------------

    def _connecting(self, now: float) -> None:
        st = self.link.state
        if st.link_ok(now) and st.pos_ned_m is not None:
            if not self.cmd.connected and not self.exit_requested:
                self._note_once("Waiting for the joystick before taking off (a FIFO needs its writer).")
                return
            problems: list[str] = getattr(self.sticks, "rest_problems", list)()
            if problems and not self.exit_requested:  # a trigger at full deflection would fly the vehicle away
                for problem in problems:
                    self._note_once(f"Not taking off: {problem}")
                return
            self._linkw.update(True)
            self._on_connected()
        elif now - self._start_s > self.s.connect_timeout_s:
            st = self.link.state
            self._fail(no_vehicle_message(self.link.transport.description, st.last_heartbeat_s is not None,
                                          self.s.connect_timeout_s))

    def _on_connected(self) -> None:
        st = self.link.state
        self._note("info", f"Connected to vehicle {st.sysid} on {self.link.transport.description} ({st.mode}, "
                           f"{'armed' if st.armed else 'disarmed'}).")
        self.link.request_home()
        self._restarts_seen = st.restarts  # a restart before we flew is nothing to report
        if st.armed:  # taking over a flight: PX4 set its home when it armed (until HOME_POSITION comes: here)
            self._home_from_vehicle = True
            self.fence = replace(self.fence, home_ned_m=st.home_ned_m or self._vehicle_pos())
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
        st = self.link.state
        if not st.armed and st.mode not in ARMABLE_MODES and self._hold_requests < 2:
            self._switch_to_hold_first(now)  # before the readiness wait: PX4 reports ready for the current mode
            return
        if self._prestreamed >= self.s.prestream_count and self._vehicle_ready(now):
            self._set_phase(Phase.ENTERING if self.link.state.armed else Phase.ARMING)

    def _vehicle_ready(self, now: float) -> bool:
        """Armed already, or its heartbeat says STANDBY (checks pass), or we waited long enough to ask anyway."""
        st = self.link.state
        if st.armed or st.system_status == MAV_STATE_STANDBY or now - self._phase_s > READY_WAIT_S:
            return True
        self._note_once("Waiting for the vehicle to be ready to arm (its HEARTBEAT does not say STANDBY yet).")
        return False

    def _arming(self, now: float) -> None:
        assert self.sp is not None
        self._send(self.sp)
        handle = self._retry.handle if self._retry is not None else None
        if self.link.state.armed or (handle is not None and handle.accepted):
            # PX4 ACKs ARM_DISARM after the state changed (px4-behaviour.md 11.6); the 1 Hz HEARTBEAT follows later
            self._note("info", "Armed.")
            self._set_phase(Phase.ENTERING)
            return
        if self.link.state.mode not in ARMABLE_MODES and self._hold_requests < 2:
            self._switch_to_hold_first(now)
            return
        if self._retry is None:
            self._retry = Retry("Arming", self.s.arm_attempts, now)
        outcome = self._retry.update(now, self.link, self.link.arm, lambda: self.link.state.armed)
        self._report_retry(outcome)

    def _switch_to_hold_first(self, now: float) -> None:
        """Ask for Hold (as MAVSDK's arm() does from Mission/Return), twice at most, then arm anyway and let the
        vehicle's refusal explain."""
        if now - self._hold_sent_s > 1.5:  # the 1 Hz HEARTBEAT shows the new mode within about a second
            self._note("info", f"Switching the vehicle from {self.link.state.mode} to Hold before arming.")
            self.link.set_mode(MAIN_AUTO, SUB_AUTO_LOITER)
            self._hold_sent_s = now
            self._hold_requests += 1

    def _entering(self, now: float) -> None:
        assert self.sp is not None
        self._send(self.sp)
        st = self.link.state
        if st.offboard and st.armed:
            self._note("info", "OFFBOARD: you have control.")
            self._set_phase(Phase.FLYING)
            return
        if not st.armed and now - self._phase_s > 2.5:  # the heartbeat should show the arming within ~1 s
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
            recent = [t.text for t in self.link.statustexts if self.clock.now() - t.time_s < 3.0]
            self._note("warn", left_offboard_message(st.mode, recent))
            self._set_phase(Phase.PAUSED if st.armed else Phase.GROUNDED)
            return
        if not st.armed:  # killed, or disarmed by another ground station
            self._note("warn", "The vehicle disarmed: joyfly stopped sending setpoints; press ARM or TAKEOFF to fly.")
            self._set_phase(Phase.GROUNDED)
            return
        self._send_flight_setpoint()

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
        elif self._joy.lost:  # a script that ended, a joystick unplugged after the flight: nothing more to fly
            self._note("info", "The joystick is gone and the vehicle is on the ground, disarmed: joyfly is done.")
            self._set_phase(Phase.DONE)

    # --- exit ----------------------------------------------------------------------------------------------------

    def _begin_exit(self) -> None:
        if self.phase is Phase.CONNECTING or not self._maybe_armed():
            self._set_phase(Phase.DONE)
            return
        self._note("info", f"Exiting: {self.s.on_exit} (press Ctrl-C again to quit at once).")
        self._set_phase(Phase.EXITING)

    def _maybe_armed(self) -> bool:
        """Armed, or an ARM was sent and not refused (PX4 ACKs it at once, the 1 Hz HEARTBEAT shows it later):
        leaving then would leave an armed vehicle behind."""
        handle = self._retry.handle if self.phase is Phase.ARMING and self._retry is not None else None
        arming = handle is not None and (handle.accepted or not handle.done)
        return self.link.state.armed or arming or self.phase is Phase.ENTERING

    def _exiting(self, now: float) -> None:
        if self._exit is None:
            self._exit = ExitPlan(self.s.on_exit, self.link, now)
        if self.link.state.offboard and self.sp is not None:  # until the vehicle switched, keep it fed
            self._send(replace(self.sp, vel_ned_m_s=(0.0, 0.0, 0.0) if self.sp.vel_ned_m_s else None))
        outcome = self._exit.update(now)
        if outcome == "done":
            self._note("info", "Landed and disarmed." if self.s.on_exit != "hold" else "The vehicle holds position.")
            self._set_phase(Phase.DONE)
            return
        if outcome:
            self._note("warn", outcome)
        self._tick_exit_timeout(now)

    def _tick_exit_timeout(self, now: float) -> None:
        if self.phase is Phase.EXITING and now - self._phase_s > self.s.exit_timeout_s:
            self._note("error", f"The vehicle did not finish '{self.s.on_exit}' within {self.s.exit_timeout_s:g} s; "
                                "it may still be armed: take over with a ground station.")
            self._set_phase(Phase.DONE)

    # --- view ------------------------------------------------------------------------------------------------


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
