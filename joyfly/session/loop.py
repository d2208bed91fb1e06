"""The part of a flight session every way of flying shares: the loop (a tick every 1/rate s, the sticks read in
between), the phases around the flight itself (connecting, landing, on the ground, the exit), the buttons and the
hooks a way of flying fills in. `FlightSession` (joyfly/session/flight_session.py) flies OFFBOARD setpoints,
`ManualSession` (joyfly/session/manual_session.py) PX4's Position and Altitude modes with MANUAL_CONTROL.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import replace

from joyfly.session.core import MIN_SEND_GAP_S, Level, Phase, SessionView, no_vehicle_message
from joyfly.session.retry import ExitPlan, Outcome, exits_by_disarming
from joyfly.session.watch import SessionWatch
from joyfly.sticks.mapping import fired
from joyfly.types import Action
from px4common.modes import AutoSubMode, MainMode

MAV_STATE_STANDBY = 3  # HEARTBEAT.system_status once PX4's arming checks pass (px4-behaviour.md 2.4)
READY_WAIT_S = 10.0  # then try to arm anyway, so the vehicle's refusal explains what is missing

log = logging.getLogger("joyfly.session.flight_session")


class SessionLoop(SessionWatch):
    """Run with `run()`; `request_exit()` (e.g. from SIGINT) performs the --on-exit action and finishes."""

    fly_again = "fly again"  # what the OFFBOARD button does after HOLD, in the note
    disarm_phases: tuple[Phase, ...] = (Phase.PAUSED, Phase.GROUNDED)  # where a held ARM disarms a landed vehicle

    # --- hooks of a way of flying ------------------------------------------------------------------------------

    def _start_control(self, why: str) -> None:
        """Begin flying (from the ground: arm and take off; in the air: take control)."""
        raise NotImplementedError

    def _take_over(self) -> None:
        """At connection: the vehicle is armed and already in joyfly's mode."""
        raise NotImplementedError

    def _send_on_change(self) -> None:
        """A stick changed: send at once (between the ticks)."""
        raise NotImplementedError

    def _after_tick(self, now: float) -> None:
        """After the phase's step, with the link up (the manual stream goes out here)."""

    def _keep_fed_while_exiting(self) -> None:
        """While the exit action starts: keep the vehicle's input alive."""

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
                self._send_on_change()
                return
            wait = min(gap, next_tick - now)
        else:
            wait = next_tick - now
        if wait > 1e-6:
            self.clock.sleep(wait)

    def _send_now_possible(self) -> bool:
        return self._dirty and self.phase is Phase.FLYING and self._streaming_allowed()

    def tick(self) -> None:
        """One period: read telemetry, run the watchdogs and the phase, stream what the way of flying streams."""
        now = self.clock.now()
        self.link.poll(0.0)
        self.link.tick()
        for text in self.link.take_new_statustexts():
            self._note(Level.WARN if text.severity <= 4 else Level.INFO, f"Vehicle: {text.text}")
        self._update_stats(now)
        self._last_tick_s = now
        if self.exit_requested and self.phase not in (Phase.EXITING, Phase.DONE, Phase.FAILED):
            self._begin_exit()
        if self.phase is not Phase.CONNECTING:
            self._watch_vehicle(now)
            if not self._watch_link(now):
                self._tick_exit_timeout(now)
                return
            self._watch_fence(now)
        if self._sticks_gone_before_arming():
            return
        self._watch_joystick(now)
        if self.phase not in (Phase.EXITING, Phase.CONNECTING):
            self._handle_buttons()
        getattr(self, _PHASE_METHODS[self.phase])(now)
        self._after_tick(now)

    def _sticks_gone_before_arming(self) -> bool:
        """A joystick gone for good (it sent no js_events, its capture ended) before anything armed ends the session
        with its sentence, a mistake in the joystick (exit status 2); after that it is a lost joystick (hold, then
        land)."""
        if self.phase not in (Phase.CONNECTING, Phase.PRESTREAM, Phase.ARMING, Phase.ENTERING) or self._maybe_armed():
            return False
        why: str | None = getattr(self.sticks, "gone", lambda: None)()
        if why is not None:
            self._fail(why, mistake=True)
        return why is not None

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
            self._note(Level.INFO, "LAND pressed: landing.")
            self.link.land()
            self._set_phase(Phase.LANDING)
        elif action is Action.RETURN and st.armed:
            self._note(Level.INFO, "RETURN pressed: returning to launch.")
            self.link.return_to_launch()
            self._set_phase(Phase.LANDING)
        elif action is Action.HOLD and st.armed:
            self._note(Level.INFO,
                       f"HOLD pressed: the vehicle holds in AUTO.LOITER; press OFFBOARD to {self.fly_again}.")
            self.link.set_mode(MainMode.AUTO, AutoSubMode.LOITER)
            self._set_phase(Phase.PAUSED)
        elif action is Action.ARM and st.armed and st.on_ground and self.phase in self.disarm_phases:
            self._note(Level.INFO, "ARM held: disarming.")
            self.link.arm(False)
        elif action in (Action.OFFBOARD, Action.TAKEOFF, Action.ARM) and self.phase in (
                Phase.PAUSED, Phase.GROUNDED, Phase.LANDING):
            self._start_control(f"{action.value.upper()} pressed")

    def _home_here(self) -> None:
        """Centre the fence (and measure altitudes from) where joyfly arms the vehicle: PX4 sets its home there when
        it arms (COM_HOME_EN, Commander::arm), so a HOME_POSITION read before arming is the last flight's home."""
        self._home_from_vehicle, self.home_known = False, True
        self.fence = replace(self.fence, home_ned_m=self._vehicle_pos())

    # --- phases around the flight --------------------------------------------------------------------------------

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
            taken: bool | None = getattr(self.link.transport, "vehicle_port_taken", lambda: None)()
            self._fail(no_vehicle_message(self.link.transport.description, st.last_heartbeat_s is not None,
                                          self.s.connect_timeout_s, taken))

    def _on_connected(self) -> None:
        st = self.link.state
        self._note(Level.INFO, f"Connected to vehicle {st.sysid} on {self.link.transport.description} ({st.mode}, "
                           f"{'armed' if st.armed else 'disarmed'}).")
        self.link.request_home()
        self._restarts_seen = st.restarts  # a restart before we flew is nothing to report
        if st.armed:  # taking over a flight: PX4 set its home when it armed (until HOME_POSITION comes: here)
            self._home_from_vehicle = self.home_known = True
            self.fence = replace(self.fence, home_ned_m=st.home_ned_m or self._vehicle_pos())
        if self.exit_requested:
            self._set_phase(Phase.DONE)
        elif st.armed and self.in_control(st):
            self._take_over()
        elif st.armed and not st.on_ground:
            self._note(Level.WARN, f"The vehicle is already flying in {st.mode}: press OFFBOARD to take control.")
            self._set_phase(Phase.PAUSED)
        else:
            self._start_control("Start")

    def _vehicle_ready(self, now: float) -> bool:
        """Armed already, or its heartbeat says STANDBY (checks pass), or we waited long enough to ask anyway."""
        st = self.link.state
        if st.armed or st.system_status == MAV_STATE_STANDBY or now - self._phase_s > READY_WAIT_S:
            return True
        self._note_once("Waiting for the vehicle to be ready to arm (its HEARTBEAT does not say STANDBY yet).")
        return False

    def _report_retry(self, outcome: Outcome | None) -> None:
        if outcome is None or self._retry is None:
            return
        if outcome is Outcome.REFUSED:
            self._note(Level.WARN, self._retry.last_refusal)
        elif outcome is Outcome.FAILED:
            if self.link.state.on_ground and self.link.state.armed:
                self.link.arm(False)
            self._fail(self._retry.failure_message())

    def _paused(self, now: float) -> None:
        st = self.link.state
        if not st.armed:
            self._note(Level.INFO, "The vehicle is on the ground and disarmed.")
            self._set_phase(Phase.GROUNDED)

    def _landing(self, now: float) -> None:
        if not self.link.state.armed:
            self._note(Level.INFO, "Landed and disarmed.")
            self._set_phase(Phase.GROUNDED)

    def _grounded(self, now: float) -> None:
        if self.s.exit_when_landed:
            self._set_phase(Phase.DONE)
        elif self._joy.lost:  # a script that ended, a joystick unplugged after the flight: nothing more to fly
            self._note(Level.INFO, "The joystick is gone and the vehicle is on the ground, disarmed: joyfly is done.")
            self._set_phase(Phase.DONE)

    def _idle(self, now: float) -> None:
        """DONE and FAILED: nothing more to do."""

    # --- exit ----------------------------------------------------------------------------------------------------

    def _begin_exit(self) -> None:
        if self.phase is Phase.CONNECTING or not self._maybe_armed():
            self._set_phase(Phase.DONE)
            return
        what = "disarming on the ground" if exits_by_disarming(self.link.state) else self.s.on_exit
        self._note(Level.INFO, f"Exiting: {what} (press Ctrl-C again to quit at once).")
        self._set_phase(Phase.EXITING)

    def _maybe_armed(self) -> bool:
        """Armed, or an ARM was sent and not refused (PX4 ACKs it at once, the 1 Hz HEARTBEAT shows it later):
        leaving then would leave an armed vehicle behind."""
        handle = self._retry.handle if self.phase is Phase.ARMING and self._retry is not None else None
        arming = handle is not None and (handle.accepted or not handle.done)
        return self.link.state.armed or arming or self.phase is Phase.ENTERING

    def _exiting(self, now: float) -> None:
        if self._exit is None:
            self._exit = ExitPlan(self.s.on_exit, self.link, now, self.in_control)
        self._keep_fed_while_exiting()
        outcome = self._exit.update(now)
        if outcome is Outcome.DONE:
            done = "Landed and disarmed." if self.s.on_exit != "hold" else "The vehicle holds position."
            done = "Disarmed on the ground." if self._exit.disarming else done
            self._note(Level.INFO, done)
            self._set_phase(Phase.DONE)
            return
        if outcome is not None:
            self._note(Level.WARN, self._exit.retry.last_refusal)
        self._tick_exit_timeout(now)

    def _tick_exit_timeout(self, now: float) -> None:
        if self.phase is Phase.EXITING and now - self._phase_s > self.s.exit_timeout_s:
            self._note(Level.ERROR, f"The vehicle did not finish '{self.s.on_exit}' within "
                       f"{self.s.exit_timeout_s:g} s; it may still be armed: take over with a ground station.")
            self._set_phase(Phase.DONE)


# Each phase's step, by method name, so that a way of flying overrides the steps it does differently
_PHASE_METHODS: dict[Phase, str] = {
    Phase.CONNECTING: "_connecting",
    Phase.PRESTREAM: "_prestream",
    Phase.ARMING: "_arming",
    Phase.ENTERING: "_entering",
    Phase.RESUMING: "_resuming",
    Phase.FLYING: "_flying",
    Phase.PAUSED: "_paused",
    Phase.LANDING: "_landing",
    Phase.GROUNDED: "_grounded",
    Phase.EXITING: "_exiting",
    Phase.DONE: "_idle",
    Phase.FAILED: "_idle",
}
