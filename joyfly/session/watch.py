"""The flight session's watchdogs, run every tick once connected: the vehicle (did it restart? is it armed? the home
of a flight joyfly took over), the link (lost, back) and the joystick (lost, back, lost too long). `FlightSession`
(joyfly/session/flight_session.py) runs them; the state they keep is `SessionCore`'s."""

from __future__ import annotations

from dataclasses import replace

from joyfly.link.vehicle_link import LINK_TIMEOUT_S
from joyfly.session.core import STALE_S, STREAMING_PHASES, Level, Phase, SessionCore, restarted_message
from joyfly.session.fence_watch import FenceChange, breach_message
from joyfly.session.watchdogs import Change
from px4common.modes import AutoSubMode, MainMode

LINK_REMINDER_S = 30.0  # while the link stays lost, say so again this often (a silent wait looks like a hang)


class SessionWatch(SessionCore):
    """The watchdog steps of the flight session's tick."""

    fly_again: str  # what the OFFBOARD button does after a Hold, in the notes (SessionLoop)

    def _watch_vehicle(self, now: float) -> None:
        """Once connected: a restart of the vehicle ends the flight; otherwise note that it is (still) armed, and
        keep the fence on the home of a flying vehicle joyfly took over."""
        st = self.link.state
        if st.restarts != self._restarts_seen:
            self._restarts_seen = st.restarts
            self._on_restart(now)
            return
        self.armed_seen |= st.armed
        self.airborne_mode = st.mode if st.armed and not st.on_ground else None
        if self._home_from_vehicle and st.home_ned_m is not None and st.home_ned_m != self.fence.home_ned_m:
            self.fence = replace(self.fence, home_ned_m=st.home_ned_m)

    def _on_restart(self, now: float) -> None:
        """The flight is over: say so, and forget what belonged to it (the setpoint, and the home, which the new
        vehicle's frame knows nothing of: the fence margin is unknown until joyfly arms it again)."""
        quitting = self.exit_requested or self.s.exit_when_landed
        self._note(Level.WARN, restarted_message(self.link.state, quitting))
        if self.airborne_mode is not None:  # last heard flying: the flight ended without a landing
            self.unlanded = f"the vehicle restarted while it flew in {self.airborne_mode} (last heard armed in the air)"
        self._restart_s, self.airborne_mode = now, None
        self.sp, self._last_pos, self._home_from_vehicle, self.home_known = None, None, False, False
        self.fence_watch.reset()
        self._set_phase(Phase.DONE if quitting else Phase.GROUNDED)

    def _watch_fence(self, now: float) -> None:
        """Warn at once when the flying vehicle is outside joyfly's fence, say when it is back, and carry out
        --fence-action once it has stayed outside for the grace time (joyfly/session/fence_watch.py)."""
        st, watch = self.link.state, self.fence_watch
        if st.stamped_s is None or now - st.stamped_s > STALE_S:
            return  # no news of the vehicle's position: nothing to judge, and a breach under way goes on
        change = watch.update(self._fence_margin(), now)
        self.stats = replace(self.stats, fence_breaches=watch.count, deepest_breach_m=watch.deepest_m)
        if change is FenceChange.OUT and watch.breach is not None:
            self._note(Level.WARN, breach_message(watch.breach.depth_m, self.fence.half_width_m, self.s.fence_action))
        elif change is FenceChange.BACK:
            self._note(Level.INFO, "The vehicle is back inside the fence.")
        if watch.due(now):
            self._fence_act(now)

    def _fence_margin(self) -> float | None:
        """The flying vehicle's fence margin (negative outside); None when there is nothing to judge: no fence or
        no home yet, no position, on the ground or disarmed."""
        st = self.link.state
        pos = st.pos_ned_m
        if not self.fence.enabled or not self.home_known or pos is None or not st.armed or st.on_ground:
            return None
        return self.fence.margin_m(pos)

    def _fence_act(self, now: float) -> None:
        """--fence-action, once the vehicle stayed outside for the grace time without coming back, if joyfly flies
        it (in another mode a failsafe, another ground station or the pilot's own command is in charge: joyfly does
        not fight it)."""
        action, st, breach = self.s.fence_action, self.link.state, self.fence_watch.breach
        assert breach is not None  # due() says so
        where = (f"The vehicle has been outside the fence for {now - breach.since_s:.1f} s and is not coming back "
                 f"({breach.depth_m:.1f} m outside)")
        if action == "warn":
            self._note(Level.WARN, f"{where}: joyfly only warns (--fence-action warn); fly it back, or press LAND "
                                   "or RETURN.")
        elif self.phase is not Phase.FLYING:
            self._note(Level.WARN, f"{where}, in {st.mode}, which joyfly does not command: --fence-action {action} "
                                   "is not carried out.")
        elif action == "hold":
            self._note(Level.WARN, f"{where}: holding in AUTO.LOITER (--fence-action hold); press OFFBOARD to "
                                   f"{self.fly_again}.")
            self.link.set_mode(MainMode.AUTO, AutoSubMode.LOITER)
            self._set_phase(Phase.PAUSED)
        elif action == "rtl":
            self._note(Level.WARN, f"{where}: returning to launch (--fence-action rtl).")
            self.link.return_to_launch()
            self._set_phase(Phase.LANDING)
        else:
            self._note(Level.WARN, f"{where}: landing where it is (--fence-action land).")
            self.link.land()
            self._set_phase(Phase.LANDING)

    def _watch_link(self, now: float) -> bool:
        st = self.link.state
        lost_s = self._linkw.lost_s
        change = self._linkw.update(st.link_ok(now), now, st.stamped_s)
        if change is Change.LOST:
            self._link_note_s = now
            self._note(Level.WARN, f"Link lost: no HEARTBEAT from the vehicle for {LINK_TIMEOUT_S:g} s; still trying "
                                   f"on {self.link.transport.description}.")
        elif not self._linkw.ok and lost_s is not None and now - self._link_note_s >= LINK_REMINDER_S:
            self._link_note_s = now
            silent_s = now - lost_s + LINK_TIMEOUT_S
            self._note(Level.WARN, f"Still no HEARTBEAT after {silent_s:.0f} s: joyfly keeps trying on "
                                   f"{self.link.transport.description} (Ctrl-C quits; the vehicle's own link-loss "
                                   "failsafe acts meanwhile).")
        elif change is Change.BACK and (lost_s is None or self._restart_s < lost_s):  # else the restart note said it
            self._note(Level.INFO, "Link back: the vehicle answers again.")
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
        why: str | None = getattr(self.sticks, "gone", lambda: None)() if change is Change.LOST else None
        if why is not None:
            self._note(Level.WARN, why)
        if change is Change.LOST and self.phase is Phase.FLYING:
            self._hold_for_joystick()
        elif change is Change.LOST and self.phase is Phase.LANDING:
            self._note(Level.WARN, "Joystick lost: the vehicle keeps landing; joyfly quits once it has disarmed.")
        elif change is Change.LOST and self.phase is not Phase.GROUNDED:  # landed: _grounded says it
            self._note(Level.WARN, "Joystick lost.")
        elif change is Change.BACK:
            self._note(Level.INFO, "Joystick back: you have control again.")
            self._joystick_back()
        if self._joy.expired(now) and self.phase is Phase.FLYING:
            self._note(Level.WARN, f"Joystick still lost after {self.s.joy_timeout_s:g} s: landing.")
            self.link.land()
            self._set_phase(Phase.LANDING)

    def _hold_for_joystick(self) -> None:
        """The joystick went away in flight: hold until it comes back or the timeout lands the vehicle."""
        self._note(Level.WARN, f"Joystick lost: holding position; landing in {self.s.joy_timeout_s:g} s "
                           "unless it comes back.")
        self.sp = self._hold_here()

    def _joystick_back(self) -> None:
        """The joystick came back (the sticks fly again from the next setpoint)."""
