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
from dataclasses import replace

from joyfly.link.vehicle_link import VehicleState
from joyfly.session.core import (
    FlightStats,
    Level,
    Note,
    Phase,
    SessionSettings,
    SessionView,
    StickSource,
    left_offboard_message,
)
from joyfly.session.loop import MAV_STATE_STANDBY, READY_WAIT_S, SessionLoop
from joyfly.session.retry import Retry
from joyfly.sticks.setpoints import initial_setpoint, next_setpoint
from px4common.modes import AutoSubMode, MainMode

__all__ = ["MAV_STATE_STANDBY", "READY_WAIT_S", "FlightSession", "FlightStats", "Level", "Note", "Phase",
           "SessionSettings", "SessionView", "StickSource"]

# Arm only in Hold or OFFBOARD: PX4 refuses to arm in Return, Land, Descend... (mode_req_prevent_arming,
# ModeUtil/mode_requirements.cpp) and in the manual modes without RC (px4-behaviour.md 3.2)
ARMABLE_MODES = ("AUTO.LOITER", "OFFBOARD")

log = logging.getLogger(__name__)


class FlightSession(SessionLoop):
    """OFFBOARD: run with `run()`; `request_exit()` (e.g. from SIGINT) performs the --on-exit action and finishes."""

    def in_control(self, st: VehicleState) -> bool:
        return st.offboard

    # --- sending -----------------------------------------------------------------------------------------------

    def _send_on_change(self) -> None:
        self._send_flight_setpoint()

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

    def _keep_fed_while_exiting(self) -> None:
        if self.link.state.offboard and self.sp is not None:  # until the vehicle switched, keep it fed
            self._send(replace(self.sp, vel_ned_m_s=(0.0, 0.0, 0.0) if self.sp.vel_ned_m_s else None))

    # --- taking control ----------------------------------------------------------------------------------------

    def _start_control(self, why: str) -> None:
        st = self.link.state
        if st.armed and not st.on_ground:
            self._note(Level.INFO, f"{why}: taking control at the current position.")
            self.sp = self._hold_here()
        else:
            self._note(Level.INFO, f"{why}: taking off to {self.s.alt_m:g} m.")
            self._home_here()
            self.sp = initial_setpoint(self._vehicle_pos(), st.yaw_rad, self.fence, self.s.alt_m)
        self._prestreamed = 0
        self._hold_requests = 0
        self._set_phase(Phase.PRESTREAM)

    def _take_over(self) -> None:
        self._note(Level.INFO, "The vehicle is already in OFFBOARD: taking over at its position.")
        self.sp = self._hold_here()
        self._set_phase(Phase.FLYING)

    # --- phases --------------------------------------------------------------------------------------------------

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

    def _arming(self, now: float) -> None:
        assert self.sp is not None
        self._send(self.sp)
        handle = self._retry.handle if self._retry is not None else None
        if self.link.state.armed or (handle is not None and handle.accepted):
            # PX4 ACKs ARM_DISARM after the state changed (px4-behaviour.md 11.6); the 1 Hz HEARTBEAT follows later
            self._note(Level.INFO, "Armed.")
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
            self._note(Level.INFO, f"Switching the vehicle from {self.link.state.mode} to Hold before arming.")
            self.link.set_mode(MainMode.AUTO, AutoSubMode.LOITER)
            self._hold_sent_s = now
            self._hold_requests += 1

    def _entering(self, now: float) -> None:
        assert self.sp is not None
        self._send(self.sp)
        st = self.link.state
        if st.offboard and st.armed:
            self._note(Level.INFO, "OFFBOARD: you have control.")
            self._set_phase(Phase.FLYING)
            return
        if not st.armed and now - self._phase_s > 2.5:  # the heartbeat should show the arming within ~1 s
            self._note(Level.WARN, "The vehicle disarmed before OFFBOARD was entered.")
            self._set_phase(Phase.GROUNDED)
            return
        if self._retry is None:
            self._retry = Retry("Switching to OFFBOARD", self.s.arm_attempts, now)
        outcome = self._retry.update(now, self.link, lambda: self.link.set_mode(MainMode.OFFBOARD),
                                     lambda: self.link.state.offboard)
        self._report_retry(outcome)

    def _resuming(self, now: float) -> None:
        assert self.sp is not None
        self._send(self.sp)
        if self.link.state.offboard:
            self._note(Level.INFO, "The vehicle is back in OFFBOARD: you have control.")
            self._set_phase(Phase.FLYING)
        elif now - self._phase_s > 2.0:
            self._note(Level.WARN, f"The vehicle stays in {self.link.state.mode}: press OFFBOARD to take control.")
            self._set_phase(Phase.PAUSED)

    def _flying(self, now: float) -> None:
        st = self.link.state
        if not st.offboard:
            recent = [t.text for t in self.link.statustexts if self.clock.now() - t.time_s < 3.0]
            self._note(Level.WARN, left_offboard_message(st.mode, recent))
            self._set_phase(Phase.PAUSED if st.armed else Phase.GROUNDED)
            return
        if not st.armed:  # killed, or disarmed by another ground station
            self._note(Level.WARN,
                       "The vehicle disarmed: joyfly stopped sending setpoints; press ARM or TAKEOFF to fly.")
            self._set_phase(Phase.GROUNDED)
            return
        self._send_flight_setpoint()
