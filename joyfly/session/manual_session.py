"""PX4's Position and Altitude modes flown with MANUAL_CONTROL, the way QGroundControl's joystick flies them
(`joyfly fly --control position` / `--control altitude`).

The order (PX4 main: Commander.cpp, manual_control, mavlink_receiver.cpp; the reference ../px4-manual cases):
1. MANUAL_CONTROL streams at --rate (25 Hz, QGC's default) with centred sticks: PX4 takes it as its RC
   (COM_RC_IN_MODE 1) and counts it present while it keeps arriving (lost COM_RC_LOSS_T, 0.5 s, after the last);
2. DO_SET_MODE POSCTL (base 1, main 3, sub 0) or ALTCTL (main 2): PX4 accepts any mode while disarmed;
3. once its HEARTBEAT shows that mode and says STANDBY (in these modes the arming checks need the sticks present),
   ARM: PX4 checks the throttle (at most 0.2, z <= 600, in POSCTL/ALTCTL); joyfly's centred z = 500 passes;
4. armed: the sticks as mapped (joyfly/sticks/manual.py), behind the throttle interlock, limited by the fence
   (joyfly/sticks/manual_fence.py). PX4 takes off once the throttle passes 0.3 (z > 650), climbs and descends with
   it and holds position and altitude with centred sticks; it disarms again if it has not taken off within
   COM_DISARM_PRFLT (10 s).

PX4 takes a MANUAL_CONTROL stream that stops for a lost RC: Hold for COM_FAIL_ACT_T (5 s), then NAV_RCL_ACT (Return),
in every mode but Land and Return (failsafe.cpp). So joyfly streams from the connection until it is done, with
centred sticks whenever the pilot does not fly (before arming, while holding for a lost joystick, while landing on
exit), and stops once the vehicle is disarmed or the user quits. Joystick lost: Hold (AUTO.LOITER), then NAV_LAND
after --joy-timeout; Ctrl-C: NAV_LAND and wait for the disarm (on the ground: disarm at once). During a link outage
joyfly sends nothing (it no longer knows where the vehicle is, so it cannot keep the fence): PX4's failsafe holds,
then returns. In Hold, Return
or Land the sticks still stream: moving them hands control back as PX4 does (its pilot takeover), as does OFFBOARD.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

from joyfly.link.vehicle_link import CommandHandle, VehicleLink, VehicleState
from joyfly.session.core import Level, Note, Phase, SessionSettings, StickSource
from joyfly.session.loop import SessionLoop
from joyfly.session.retry import Retry
from joyfly.sticks.manual import CENTRED, ManualInput, interlock, to_manual
from joyfly.sticks.manual_fence import (
    PX4,
    ManualModel,
    SetpointEstimate,
    advance_estimate,
    limit_tracked,
    restart_estimate,
)
from joyfly.types import Clock
from px4common.modes import AutoSubMode, MainMode, main_mode

# --control -> (PX4 main mode, its name, in words)
MANUAL_MODES: dict[str, tuple[int, str, str]] = {
    "position": (MainMode.POSCTL, "POSCTL", "Position mode"),
    "altitude": (MainMode.ALTCTL, "ALTCTL", "Altitude mode"),
}
MANUAL_CONTROLS = tuple(MANUAL_MODES)
STICK_MODES = (MainMode.POSCTL, MainMode.ALTCTL)  # where joyfly's sticks fly the vehicle (PX4 may fall back to ALTCTL)
RATE_HZ = 25.0  # QGroundControl's joystick rate while the sticks move (its Axis Frequency default)
FRESH_HEARTBEAT_S = 0.1  # a HEARTBEAT this long after a mode command shows its effect (PX4 ACKs after switching)
# Centred sticks this long before joyfly's own switch to an auto mode (the exit, a lost joystick): PX4's stick
# movement filter (ManualControl.cpp MovingDiff, tau 0.05 s) forgets the sticks' last moves, so it does not take the
# vehicle straight back to Position mode ("Pilot took over using sticks")
STEADY_S = 0.3
PILOT_PHASES = (Phase.FLYING, Phase.PAUSED, Phase.LANDING)  # the pilot's sticks go out; elsewhere centred ones
_PHASE_TEXT = {Phase.PRESTREAM: "streaming MANUAL_CONTROL", Phase.ENTERING: "entering {mode}",
               Phase.ARMING: "arming in {mode}", Phase.FLYING: "flying in {mode}"}


class ManualSession(SessionLoop):
    """--control position / altitude: run with `run()`; `request_exit()` lands (see --on-exit) and finishes."""

    fly_again = "take control again"
    disarm_phases = (Phase.PAUSED, Phase.GROUNDED, Phase.FLYING)  # FLYING: armed, waiting for the throttle

    def __init__(self, link: VehicleLink, sticks: StickSource, clock: Clock, settings: SessionSettings,
                 on_note: Callable[[Note], None] | None = None, model: ManualModel = PX4) -> None:
        super().__init__(link, sticks, clock, settings, on_note)
        self.main_mode, self.mode_name, self.mode_words = MANUAL_MODES[settings.limits.control]
        self.model = model
        self.manual_count = 0  # MANUAL_CONTROL messages sent
        self._latched = True  # the throttle interlock (sticks/manual.py)
        self._joy_hold = False  # holding in AUTO.LOITER for a lost joystick
        self._hold_sent = False  # ... and the Hold was asked for
        self._from_air = False  # ENTERING a flying vehicle (not arming one on the ground)
        self._est = SetpointEstimate()  # PX4's POSCTL velocity setpoint, estimated from what was sent

    def in_control(self, st: VehicleState) -> bool:
        return st.last_heartbeat_s is not None and main_mode(st.custom_mode) in STICK_MODES

    def control_label(self) -> str:
        return self.mode_name

    def phase_text(self) -> str:
        return _PHASE_TEXT.get(self.phase, self.phase.value).format(mode=self.mode_name)

    def summary_extra(self) -> list[str]:
        st = self.link.state
        sent = self.manual_sent.describe() if self.manual_sent is not None else "-"
        alt = f", {self.fence.alt_m(st.pos_ned_m):.1f} m above home" if st.pos_ned_m is not None else ""
        return [f"flown in              {self.mode_words} ({self.mode_name}), MANUAL_CONTROL at {self.s.rate_hz:g} Hz",
                f"last sticks sent      {sent}",
                f"vehicle at the end    {st.mode}, {'armed' if st.armed else 'disarmed'}{alt}"]

    # --- the stream ----------------------------------------------------------------------------------------------

    def _streaming_allowed(self) -> bool:
        return self.phase not in (Phase.CONNECTING, Phase.DONE, Phase.FAILED) and self._linkw.ok

    def _send_now_possible(self) -> bool:
        return False  # a steady stream, as QGC's: a stick change goes out with the next tick (at most 40 ms later)

    def _send_on_change(self) -> None:
        self._stream()

    def _after_tick(self, now: float) -> None:
        if self._streaming_allowed():
            self._stream()

    def _stream(self) -> None:
        inp = self._sticks_to_send()
        self.manual_sent = inp
        self._dirty = False
        self._last_sp_s = self.clock.now()
        self.link.send_manual_control(inp.x, inp.y, inp.z, inp.r)
        self.manual_count += 1

    def _sticks_to_send(self) -> ManualInput:
        """The pilot's sticks (interlocked, fenced) while armed in a pilot phase, else centred."""
        st, now = self.link.state, self.clock.now()
        mode = main_mode(st.custom_mode)
        # PX4 runs its POSCTL setpoint only in POSCTL, and restarts it from the vehicle's velocity until takeoff
        est = self._est if mode == MainMode.POSCTL and st.landed_state != 1 else restart_estimate(st.vel_ned_m_s, now)
        pilot, self._latched = interlock(to_manual(self.cmd), self._latched)  # it follows the stick in every phase
        if (not st.armed or self.phase not in PILOT_PHASES or self._joy_hold or self._joy.lost
                or self.cmd.deadman_ok is False or st.pos_ned_m is None):
            self._est = replace(advance_estimate(est, now, st.vel_ned_m_s, self.model), stick_ne=(0.0, 0.0))
            return CENTRED
        # landing by itself, the vehicle may go below --min-alt: a held throttle must not turn into a moving one
        fence = replace(self.fence, min_alt_m=-math.inf) if self.phase is Phase.LANDING else self.fence
        out, self._est = limit_tracked(pilot, st.pos_ned_m, st.vel_ned_m_s, st.yaw_rad, fence, mode == MainMode.ALTCTL,
                                       est, now, self.model)
        return out

    # --- taking control ----------------------------------------------------------------------------------------

    def _start_control(self, why: str) -> None:
        st = self.link.state
        self._joy_hold, self._latched = False, True
        self._from_air = st.armed and not st.on_ground
        if self._from_air:
            self._note(Level.INFO, f"{why}: switching to {self.mode_words} ({self.mode_name}).")
            self._set_phase(Phase.ENTERING)
            return
        self._note(Level.INFO, f"{why}: {self.mode_words} ({self.mode_name}) with MANUAL_CONTROL; arming with the "
                           "throttle centred, then the throttle stick takes off.")
        self._home_here()
        self._prestreamed = 0
        self._set_phase(Phase.PRESTREAM)

    def _take_over(self) -> None:
        self._latched = True
        self._now_flying(f"The vehicle is already flying in {self.link.state.mode}: taking over with the sticks "
                         "(the throttle acts once it has been at the centre).")

    def _now_flying(self, text: str) -> None:
        self._note(Level.INFO, text)
        self._joy_hold = False
        self._set_phase(Phase.FLYING)

    def _arm(self) -> CommandHandle:
        """ARM, the throttle interlock closed: it opens once the stick is at or below the centre (_sticks_to_send)."""
        self._latched = True
        return self.link.arm()

    def _fresh(self, st: VehicleState) -> bool:
        """A HEARTBEAT that came after this phase began (so after the command that started it took effect)."""
        return st.last_heartbeat_s is not None and st.last_heartbeat_s >= self._phase_s + FRESH_HEARTBEAT_S

    # --- phases --------------------------------------------------------------------------------------------------

    def _prestream(self, now: float) -> None:
        self._prestreamed += 1  # centred sticks go out every tick (_after_tick)
        if self._prestreamed >= self.s.prestream_count:
            self._set_phase(Phase.ENTERING)

    def _entering(self, now: float) -> None:
        st = self.link.state
        if main_mode(st.custom_mode) == self.main_mode and self._fresh(st):
            if st.armed:
                self._now_flying(f"{self.mode_words} ({self.mode_name}): you have control.")
            elif self._from_air:
                self._note(Level.WARN, f"The vehicle disarmed before {self.mode_name} was entered.")
                self._set_phase(Phase.GROUNDED)
            elif self._vehicle_ready(now):
                self._set_phase(Phase.ARMING)
            return
        if self._retry is None:
            self._retry = Retry(f"Switching to {self.mode_name}", self.s.arm_attempts, now)
        outcome = self._retry.update(now, self.link, lambda: self.link.set_mode(self.main_mode),
                                     lambda: main_mode(self.link.state.custom_mode) == self.main_mode)
        self._report_retry(outcome)

    def _arming(self, now: float) -> None:
        if self.link.state.armed:  # from the HEARTBEAT: until then the sticks stay centred
            self._now_flying(f"Armed in {self.mode_words}: push the throttle up to take off (PX4 disarms again if it "
                             "has not taken off within about 10 s).")
            return
        if self._retry is None:
            self._retry = Retry("Arming", self.s.arm_attempts, now)
        outcome = self._retry.update(now, self.link, self._arm, lambda: self.link.state.armed)
        self._report_retry(outcome)

    def _flying(self, now: float) -> None:
        st = self.link.state
        lost_s = self._joy.lost_since
        if self._joy_hold and not self._hold_sent and lost_s is not None and now - lost_s >= STEADY_S:
            self.link.set_mode(MainMode.AUTO, AutoSubMode.LOITER)
            self._hold_sent = True
        if not st.armed:
            self._note(Level.WARN, "The vehicle disarmed: press ARM or TAKEOFF to fly again.")
            self._set_phase(Phase.GROUNDED)
        elif not self._joy_hold and not self.in_control(st):
            recent = [t.text for t in self.link.statustexts if now - t.time_s < 3.0]
            why = f" ({recent[-1]})" if recent else ""
            self._note(Level.WARN, f"The vehicle left {self.mode_name} for {st.mode}{why}: press OFFBOARD to take "
                       "control again (moving the sticks also hands it back, when PX4 allows it).")
            self._set_phase(Phase.PAUSED)

    def _paused(self, now: float) -> None:
        st = self.link.state
        if st.armed and self.in_control(st) and self._fresh(st):
            self._now_flying(f"The vehicle is in {st.mode} again (the sticks took over, or another ground "
                             "station): you have control.")
        else:
            super()._paused(now)

    def _landing(self, now: float) -> None:
        st = self.link.state
        if st.armed and self.in_control(st) and self._fresh(st):
            self._now_flying(f"The vehicle is in {st.mode} again (the sticks took over): you have control.",
                             )
        else:
            super()._landing(now)

    # --- the watchdogs' steps ----------------------------------------------------------------------------------

    def _hold_for_joystick(self) -> None:
        """Hold (AUTO.LOITER), asked for once the centred sticks have been steady for STEADY_S (_flying)."""
        self._note(Level.WARN, f"Joystick lost: Hold (AUTO.LOITER) with centred sticks; landing in "
                           f"{self.s.joy_timeout_s:g} s unless it comes back.")
        self._joy_hold, self._hold_sent = True, False

    def _joystick_back(self) -> None:
        was_holding, self._joy_hold = self._joy_hold, False
        if was_holding and self.phase is Phase.FLYING:
            self._start_control("Joystick back")

    def _on_link_back(self) -> None:
        st = self.link.state
        if self.phase in (Phase.PRESTREAM, Phase.ENTERING, Phase.ARMING, Phase.FLYING) and not st.armed:
            self._set_phase(Phase.GROUNDED)
        elif self.phase is Phase.FLYING and not self._joy_hold and not self.in_control(st):
            self._note(Level.WARN, f"The vehicle is in {st.mode} after the outage (PX4's failsafe for the lost "
                               "MANUAL_CONTROL): press OFFBOARD to take control again.")
            self._set_phase(Phase.PAUSED)

    # --- exit ----------------------------------------------------------------------------------------------------

    def _maybe_armed(self) -> bool:
        handle = self._retry.handle if self.phase is Phase.ARMING and self._retry is not None else None
        return self.link.state.armed or (handle is not None and (handle.accepted or not handle.done))

    def _exiting(self, now: float) -> None:
        if self._exit is None and now - self._phase_s < STEADY_S:
            return  # centred sticks first (_sticks_to_send), then the exit command
        super()._exiting(now)
        if self.phase is Phase.DONE and self.s.on_exit == "hold" and self.link.state.armed:
            self._note(Level.WARN, "joyfly stops sending MANUAL_CONTROL now: PX4 takes that for a lost RC and, after "
                               "holding for COM_FAIL_ACT_T (5 s), returns home (NAV_RCL_ACT).")
