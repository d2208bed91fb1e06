"""PX4's commander for a SITL multicopter: arming, user mode intention vs mode in force, failsafes, auto-disarm.

A pure state machine: simulated time comes in as `now_us`, texts go out through the `emit` callback, requests for
the navigator (takeoff altitude, reposition, altitude change) queue in `nav_commands`. Commands are handled by
`sitl_emu.commander.commands.handle_command(commander, ...)`. Sources: src/modules/commander/Commander.cpp (arm ~l.663,
disarm ~l.744, handleAutoDisarm ~l.2455, takeoff completion ~l.2208, land detector texts ~l.2310),
UserModeIntention.cpp, failsafe/failsafe.cpp. See ../shared/reference/px4-behaviour.md sections 2-5.
"""

from __future__ import annotations

from collections.abc import Callable

from sitl_emu.commander import arming
from sitl_emu.commander.failsafe import Failsafe
from sitl_emu.commander.fault_failsafes import FaultFlags
from sitl_emu.commander.health_report import HealthReporter, ReportInputs
from sitl_emu.commander.manual_control import ManualControlSignal
from sitl_emu.commander.mode_intention import ModeIntention
from sitl_emu.commander.notices import SendEvent, drop, failsafe_notice_event
from sitl_emu.commander.offboard import OffboardSignal
from sitl_emu.commander.settings import CommanderSettings
from sitl_emu.commander.stick_gestures import Gesture, GestureDetector, StickMotion
from sitl_emu.control.qmath import isfinite
from sitl_emu.navigator.commands import NavCommand
from sitl_emu.navigator.geofence import NO_BREACH, GeofenceResult
from sitl_emu.navigator.mission_store import MissionStore
from sitl_emu.params import ParamRegistry
from sitl_emu.px4 import AUTO_MODES, MANUAL_MODES, MANUAL_THRUST_MODES, UI_NAMES, MavState, NavState, Severity
from sitl_emu.types import HomePosition, ManualControlSetpoint, OffboardControlMode, Vec3

Emit = Callable[[Severity, str, str, bool, bool], None]  # emit(severity, module, text, is_event, statustext)
NedOf = Callable[[float, float, float], Vec3]  # geo -> local NED: ned_of(lat_deg, lon_deg, alt_amsl_m)
# the current position as a home candidate, None while the estimator is not ready (asked when home is set)
Here = Callable[[], HomePosition | None]


def _nowhere() -> HomePosition | None:
    return None


class Commander:
    """The vehicle's brain; see the module docstring."""

    def __init__(self, params: ParamRegistry, emit: Emit, ned_of: NedOf | None = None, here: Here = _nowhere,
                 send_event: SendEvent = drop) -> None:
        self.params = params
        self._settings = CommanderSettings.from_params(params)
        self._params_watch = params.changes.watch()  # params/changes.py
        self._emit, self._send_event = emit, send_event  # texts; PX4 events no text tells (commander/notices.py)
        self._health = HealthReporter()
        self._ned_of, self._here = ned_of, here
        self.intention = ModeIntention(NavState.AUTO_LOITER)
        self._failsafe = Failsafe()
        self.armed = False
        self.nav_state: NavState = NavState.AUTO_LOITER
        self.failsafe = False
        self.terminated = False
        self.home: HomePosition | None = None
        self.have_taken_off = False
        self.landed = True
        self.maybe_landed = True
        self.nav_commands: list[NavCommand] = []
        self.reboot_requested = False
        # what the commander saw of the vehicle at the start of the current cycle (observe)
        self.now_us = 0
        self.estimator_ready = False
        self._task_finished = False
        self._ready_announced = False
        self._armed_at_us = 0
        self._landed_since_us: int | None = None
        self._offboard = OffboardSignal()  # commander/offboard.py: what happens when the setpoints stop
        self.manual = ManualControlSignal()  # commander/manual_control.py: the MAVLink joystick as RC
        self._manual_lost_at_arming = True
        self._gestures = GestureDetector()
        self._stick_motion = StickMotion()
        self._last_reject_text_us: int | None = None
        self.fault_flags = FaultFlags()  # written by the vehicle's fault monitor (vehicle/faults.py)
        self.geofence: GeofenceResult = NO_BREACH  # the navigator's geofence_result (navigator/geofence_monitor.py)
        self._checks_key: tuple[object, ...] = ()  # what pre_flight_checks_pass last ran for
        self._checks_pass = False
        self._inputs = arming.CheckInputsCache()  # the last check inputs (read-only: shared while unchanged)
        self.mission_store: MissionStore | None = None  # the stored plans (the Vehicle's), for AUTO.MISSION's checks

    @property
    def settings(self) -> CommanderSettings:
        if self._params_watch.changed():
            self._settings = CommanderSettings.from_params(self.params)
        return self._settings

    # ---- inputs -------------------------------------------------------------------------------------------------
    def observe(self, now_us: int, *, estimator_ready: bool, task_finished: bool = False) -> None:
        """The vehicle at a cycle's start: the time, the estimator ready, the navigator's task done (takeoff)."""
        self.now_us = now_us
        self.estimator_ready = estimator_ready
        self._task_finished = task_finished

    def offboard_signal(self, now_us: int, mode: OffboardControlMode) -> None:
        """An offboard_control_mode arrived (any mode): refresh the COM_OF_LOSS_T watchdog."""
        self._offboard.refresh(now_us, mode)

    def manual_control_signal(self, now_us: int, setpoint: ManualControlSetpoint) -> bool:
        """A MANUAL_CONTROL arrived (any mode); False if COM_RC_IN_MODE ignores MAVLink input. The sticks' gestures
        and a pilot's takeover act at once (commander/stick_gestures.py)."""
        regained = not self.manual_control_valid(now_us)
        if not self.manual.refresh(now_us, setpoint, self.settings.rc_in_mode):
            return False
        if regained:  # manual_control resets its gesture and movement filters while the input is invalid
            self._gestures.reset()
            self._stick_motion.reset()
        self._stick_gesture(now_us, setpoint)
        if self._stick_motion.update(now_us, setpoint, self.settings.override_speed):
            self._pilot_takeover()
        return True

    def _stick_gesture(self, now_us: int, setpoint: ManualControlSetpoint) -> None:
        """MAN_ARM_GESTURE: arm with the preflight checks; disarm only on the ground or in a manual-thrust mode (in
        the air it is refused without a word)."""
        gesture = self._gestures.update(now_us, setpoint)
        if gesture is None or not self.settings.arm_gesture:
            return
        if gesture is Gesture.ARM and not self.armed:
            self.arm(now_us, external=True, run_checks=True, reason="stick gesture")
        elif gesture is Gesture.DISARM and self.armed and self._may_disarm_by_sticks():
            self.disarm("stick gesture", forced=True)

    def _may_disarm_by_sticks(self) -> bool:
        return self.landed or self.maybe_landed or self.nav_state in MANUAL_THRUST_MODES

    def _pilot_takeover(self) -> None:
        """Commander::manualControlCheck: sticks moved in an auto mode or OFFBOARD switch to Position (Altitude if
        Position cannot run); during a failsafe action the switch ends it too."""
        if not self.armed or not (self.nav_state in AUTO_MODES or self.nav_state is NavState.OFFBOARD):
            return
        if self.nav_state is NavState.AUTO_FOLLOW_TARGET:
            return  # control_mode.cpp: Follow Target is not flag_control_auto_enabled; its sticks adjust the follow
        if self._failsafe.manual_loss.hold_s(self.now_us) > 0 or not self._failsafe.geofence.sticks_may_take_over(
                self.now_us):
            return  # no stick takeover during the Hold before a failsafe action (framework.cpp)
        in_failsafe = self.failsafe  # taking over from a failsafe action is told as an event only
        if self.change_mode(NavState.POSCTL) or self.change_mode(NavState.ALTCTL):
            self.say(Severity.INFO, "Pilot took over using sticks", statustext=not in_failsafe)

    def manual_control_valid(self, now_us: int) -> bool:
        return self.manual.valid(now_us, self.settings.rc_loss_us)

    def _manual_lost(self, inputs: arming.CheckInputs) -> bool:
        """failsafe_flags.manual_control_signal_lost, not counting a vehicle armed without manual control
        (failsafe.cpp _manual_control_lost_at_arming: ignored until the sticks first appear)."""
        if inputs.manual_control:
            self._manual_lost_at_arming = False
        return not inputs.manual_control and not self._manual_lost_at_arming

    def offboard_fresh(self, now_us: int) -> bool:
        return self._offboard.fresh(now_us, self.settings.of_loss_us)

    @property
    def offboard_mode(self) -> OffboardControlMode | None:
        """The last offboard signal kinds while the signal is fresh, else None."""
        return self._offboard.mode if self.offboard_fresh(self.now_us) else None

    @property
    def offboard_mode_last(self) -> OffboardControlMode | None:
        """The kinds of the last offboard message since boot, however old (PX4's offboard_control_mode topic)."""
        return self._offboard.mode

    # ---- checks -------------------------------------------------------------------------------------------------
    def check_inputs(self, now_us: int | None = None) -> arming.CheckInputs:
        return self._check_inputs(self.now_us if now_us is None else now_us, self.settings)

    def _check_inputs(self, now_us: int, st: CommanderSettings) -> arming.CheckInputs:
        """check_inputs with the settings already at hand (the commander cycle reads them once), shared while equal."""
        return self._inputs.of(estimator_ready=self.estimator_ready, home_valid=self.home is not None,
                               offboard_signal=self._offboard_available(now_us, st),
                               manual_control=self.manual.valid(now_us, st.rc_loss_us),
                               mission_valid=self.mission_valid, position_lost=self.fault_flags.position_lost,
                               mission_required=st.arm_mission_required)

    def _offboard_available(self, now_us: int, st: CommanderSettings) -> bool:
        """offboardCheck.cpp: a fresh signal, with the estimate its setpoints need (commander/arming.py)."""
        mode, fresh = self._offboard.mode, self._offboard.fresh(now_us, st.of_loss_us)
        estimate = arming.estimate_valid(self.estimator_ready, self.fault_flags.position_lost)
        return fresh and mode is not None and arming.offboard_available(mode, estimate)

    @property
    def mission_valid(self) -> bool:
        """failsafe_flags.auto_mission_missing inverted: a valid mission is stored."""
        return self.mission_store is not None and self.mission_store.mission_valid

    def can_run(self, nav_state: NavState) -> bool:
        return arming.can_run(nav_state, self.check_inputs())

    def pre_flight_checks_pass(self) -> bool:
        """Arming checks pass for the current nav_state (drives system_status STANDBY vs UNINIT when disarmed).

        PX4 runs these checks once per commander cycle; here they run at most once per cycle (the commander's
        now_us) and again when the mode, the arming state or the geofence result changes, however many snapshots
        ask in between."""
        key = (self.now_us, self.nav_state, self.armed, self.geofence)
        if key != self._checks_key:
            self._checks_key = key
            self._checks_pass = arming.can_arm(self.nav_state, self.check_inputs(), self.armed) and \
                not self.geofence.breached
        return self._checks_pass

    def system_status(self) -> MavState:
        """HEARTBEAT.system_status as PX4's src/modules/mavlink/streams/HEARTBEAT.hpp sets it: armed, ACTIVE (CRITICAL
        in a failsafe); disarmed, STANDBY only while the arming checks pass in the current mode, else UNINIT. So a
        vehicle left in OFFBOARD after an OFFBOARD flight says UNINIT until it gets setpoints or another mode, as
        recorded from PX4 SITL (shared reference px4-recorded-facts.md, section 5)."""
        if self.nav_state is NavState.TERMINATION and self.armed:
            return MavState.FLIGHT_TERMINATION
        if self.armed:
            return MavState.CRITICAL if self.failsafe else MavState.ACTIVE
        return MavState.STANDBY if self.pre_flight_checks_pass() else MavState.UNINIT

    # ---- texts --------------------------------------------------------------------------------------------------
    def say(self, severity: Severity, text: str, is_event: bool = True, statustext: bool = True,
            module: str = "commander") -> None:
        self._emit(severity, module, text, is_event, statustext)

    def reject_mode_text(self, nav_state: NavState, now_us: int, rate_limited: bool = False) -> None:
        """printRejectMode: "Switching to %s is currently not available" (DO_SET_MODE: at most once per second)."""
        if rate_limited and self._last_reject_text_us is not None and now_us - self._last_reject_text_us < 1_000_000:
            return
        self._last_reject_text_us = now_us
        self.say(Severity.CRITICAL, f"Switching to {UI_NAMES[nav_state]} is currently not available")

    # ---- arming -------------------------------------------------------------------------------------------------
    def arm(self, now_us: int, *, external: bool, run_checks: bool, reason: str | None = None) -> bool:
        """Commander::arm: checks for the current nav_state, then arm, set home, start the auto-disarm timers."""
        if self.armed:
            return True
        if run_checks and not self._throttle_safe(now_us):
            self.say(Severity.CRITICAL, "Arming denied: throttle not in safe position")
            return False
        if run_checks:
            failure = arming.arming_failure(self.nav_state, self.check_inputs(now_us))
            if failure is not None:
                self.say(Severity.WARNING, f"Preflight Fail: {failure}", is_event=False, statustext=False,
                         module="health_and_arming_checks")
                self.say(Severity.CRITICAL, "Arming denied: Resolve system health failures first")
                return False
            if self.geofence.breached:  # geofenceCheck.cpp: a breach fails the arming checks in every mode
                for text in self.geofence.health_texts():
                    self.say(Severity.CRITICAL, text, is_event=False)
                self.say(Severity.CRITICAL, "Arming denied: Resolve system health failures first")
                return False
        self.armed = True
        self.have_taken_off = False
        self._manual_lost_at_arming = not self.manual_control_valid(now_us)
        self._armed_at_us = now_us
        self._landed_since_us = None
        self._failsafe.reset()
        here = self._here()
        if self.settings.home_enabled and here is not None:
            self.home = here
        self.say(Severity.INFO, f"Armed by {reason or ('external' if external else 'internal') + ' command'}")
        return True

    def _throttle_safe(self, now_us: int) -> bool:
        """Commander::arm's throttle check, in a manual mode with manual control present: at most 0.2 (of -1..1) where
        the sticks command a climb rate, below -0.8 where the throttle is the thrust."""
        if self.nav_state not in MANUAL_MODES or not self.manual_control_valid(now_us):
            return True
        throttle = self.manual.setpoint.throttle
        return throttle < -0.8 if self.nav_state in MANUAL_THRUST_MODES else throttle <= 0.2

    def disarm(self, reason: str, *, forced: bool) -> bool:
        """Commander::disarm: refused in the air unless forced; the mode reverts to the sticky user mode."""
        if not self.armed:
            return True
        if not forced and not (self.landed or self.maybe_landed):
            self.say(Severity.CRITICAL, "Disarming denied: not landed")
            return False
        self.armed = False
        self.have_taken_off = False
        self.say(Severity.INFO, f"Disarmed by {reason}")
        self.intention.on_disarm()
        self._failsafe.reset()
        self.failsafe = False
        if not self.terminated:
            self.nav_state = self.intention.user_intended
        return True

    # ---- modes --------------------------------------------------------------------------------------------------
    def change_mode(self, nav_state: NavState, *, force: bool = False) -> bool:
        """UserModeIntention::change; on success the mode in force follows at once when it can run."""
        ok = self.intention.change(nav_state, armed=self.armed, can_run=self.can_run(nav_state), force=force,
                                   in_termination=self.nav_state is NavState.TERMINATION)
        if ok:
            self._failsafe.reset(user_mode_change=True)  # ends the failsafe actions (OnModeChangeOrDisarm)
            self._apply_mode(self.now_us)
        return ok

    def _apply_mode(self, now_us: int) -> arming.CheckInputs:
        """The mode in force (the user's, or the failsafe's while it cannot run; termination sticks while armed)."""
        st = self.settings
        inputs = self._check_inputs(now_us, st)
        decision = self._failsafe.update(armed=self.armed, user=self.intention.user_intended, inputs=inputs,
                                         settings=st.fallback, terminated=self.terminated, now_us=now_us,
                                         manual_lost=self._manual_lost(inputs), manual_loss=st.manual_loss,
                                         faults=self.fault_flags, fault_settings=st.faults,
                                         geofence=self.geofence, fail_act_us=st.manual_loss.fail_act_us)
        if not (self.armed and self.nav_state is NavState.TERMINATION):
            self.nav_state = decision.nav_state
        self.failsafe = decision.failsafe
        if decision.activated:  # a warning has its event only (no text)
            self._send_event(failsafe_notice_event(self.intention.user_intended, decision, now_us))
            if decision.text:
                self.say(Severity.CRITICAL, decision.text)
        if decision.disarm:
            self.disarm("failsafe", forced=True)
        return inputs

    def report_health(self, now_us: int, inputs: arming.CheckInputs | None = None, force: bool = False) -> None:
        """HealthAndArmingChecks::update (10 Hz, on a status change, forced by RUN_PREARM_CHECKS): a report if due."""
        if self._health.due(now_us, self.nav_state, self.armed, force):
            st = self.settings
            checked = inputs or self._check_inputs(now_us, st)
            report = ReportInputs.of(self.nav_state, self.armed, checked, self.geofence, self.fault_flags,
                                     st.rc_in_mode == 4, st.faults.dll.rcl_act > 0)
            for event in self._health.update(now_us, report, force):
                self._send_event(event)

    # ---- the periodic update ------------------------------------------------------------------------------------
    def update(self, now_us: int) -> None:
        """One commander cycle: readiness, home, auto-disarm, takeoff completion, the mode in force."""
        self._update_ready()
        self._auto_disarm(now_us)
        self._takeoff_completion()
        self.report_health(now_us, self._apply_mode(now_us))

    def _update_ready(self) -> None:
        if not self.estimator_ready:
            return
        if self.home is None and not self.armed and self.settings.home_enabled:
            self.home = self._here()  # HomePosition::update: first valid global position on the ground
        if not self._ready_announced:
            self._ready_announced = True
            self.say(Severity.INFO, "Ready for takeoff!", is_event=False, statustext=False)

    def _auto_disarm(self, now_us: int) -> None:
        """handleAutoDisarm: COM_DISARM_LAND after landing, COM_SPOOLUP_TIME + COM_DISARM_PRFLT if never airborne."""
        if not self.armed:
            return
        st = self.settings
        if self.have_taken_off:
            if st.disarm_land_us <= 0 or not self.landed:
                self._landed_since_us = None
                return
            if self._landed_since_us is None:
                self._landed_since_us = now_us
            if now_us - self._landed_since_us >= st.disarm_land_us:
                self.disarm("landing", forced=True)
        elif st.preflight_disarm_us > 0 and now_us - self._armed_at_us >= st.preflight_disarm_us:
            self.disarm("auto preflight disarming", forced=True)

    def _takeoff_completion(self) -> None:
        """Commander.cpp ~l.2208: takeoff finished in the air -> Hold (COM_TAKEOFF_ACT 0)."""
        if self.armed and not self.landed and self._task_finished and self.nav_state is NavState.AUTO_TAKEOFF:
            self.change_mode(NavState.AUTO_LOITER)

    def on_mission_finished(self) -> None:
        """Commander::checkForMissionUpdate: a mission that finished in the air while in AUTO_MISSION hands over to
        Hold as the user's mode; so after its RTL item's return lands, the vehicle disarms into Hold, not Mission
        (../shared/reference/px4-mission/cases.json flight1/2.sequence: AUTO.LOITER disarmed)."""
        if self.armed and not self.landed and self.nav_state is NavState.AUTO_MISSION:
            self.change_mode(NavState.AUTO_LOITER)

    def on_land_detector(self, landed: bool, maybe_landed: bool) -> None:
        """Land detector output after physics: "Takeoff detected" / "Landing detected" while armed."""
        was_landed = self.landed
        self.landed, self.maybe_landed = landed, maybe_landed
        if not self.armed or landed == was_landed:
            return
        if landed:
            self.say(Severity.INFO, "Landing detected")
        else:
            self.say(Severity.INFO, "Takeoff detected")
            self.have_taken_off = True

    # ---- home ---------------------------------------------------------------------------------------------------
    def home_from_global(self, lat_deg: float, lon_deg: float, alt_amsl_m: float, yaw_rad: float) -> bool:
        """HomePosition::setManually: needs a valid local position to place home in the local frame."""
        if not self.estimator_ready or self._ned_of is None:
            return False
        pos = self._ned_of(lat_deg, lon_deg, alt_amsl_m)
        yaw = yaw_rad if isfinite(yaw_rad) else (self.home.yaw_rad if self.home else 0.0)
        self.home = HomePosition(lat_deg, lon_deg, alt_amsl_m, pos, yaw)
        return True

    def home_here(self) -> bool:
        here = self._here()
        if not self.estimator_ready or here is None:
            return False
        self.home = here
        return True
