"""The flight session's watchdogs, run every tick once connected: the vehicle (did it restart? is it armed? the home
of a flight joyfly took over), the link (lost, back) and the joystick (lost, back, lost too long). `FlightSession`
(joyfly/session/flight_session.py) runs them; the state they keep is `SessionCore`'s."""

from __future__ import annotations

from dataclasses import replace

from joyfly.link.vehicle_link import LINK_TIMEOUT_S
from joyfly.session.core import STREAMING_PHASES, Level, Phase, SessionCore, restarted_message
from joyfly.session.watchdogs import Change

LINK_REMINDER_S = 30.0  # while the link stays lost, say so again this often (a silent wait looks like a hang)


class SessionWatch(SessionCore):
    """The watchdog steps of the flight session's tick."""

    def _watch_vehicle(self, now: float) -> None:
        """Once connected: a restart of the vehicle ends the flight; otherwise note that it is (still) armed, and
        keep the fence on the home of a flying vehicle joyfly took over."""
        st = self.link.state
        if st.restarts != self._restarts_seen:
            self._restarts_seen = st.restarts
            self._on_restart(now)
            return
        self.armed_seen |= st.armed
        if self._home_from_vehicle and st.home_ned_m is not None and st.home_ned_m != self.fence.home_ned_m:
            self.fence = replace(self.fence, home_ned_m=st.home_ned_m)

    def _on_restart(self, now: float) -> None:
        quitting = self.exit_requested or self.s.exit_when_landed
        self._note(Level.WARN, restarted_message(self.link.state, quitting))
        self._restart_s = now
        self.sp, self._last_pos, self._home_from_vehicle = None, None, False
        self._set_phase(Phase.DONE if quitting else Phase.GROUNDED)

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
