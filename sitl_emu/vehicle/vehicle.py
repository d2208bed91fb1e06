"""The emulated PX4 quadrotor: one deterministic step over simulated time, and the interface the MAVLink side uses.

Vehicle.step() runs, in this fixed order, at now_us = previous time + dt_us (4000 us, 250 Hz):
 1. pending reboot (PREFLIGHT_REBOOT_SHUTDOWN param1=1, acknowledged before): back to the boot state, time 0;
 2. commander (every COMMANDER_PERIOD_US), after the navigator's geofence check (fence.py): readiness
    ("Ready for takeoff!"), home, auto-disarm, takeoff completion, failsafes, mode in force;
 3. mode executor: the navigator task of the mode in force (none while disarmed), or the offboard setpoint;
 4. control cascade: setpoint -> motor commands (zero when disarmed or terminated), then injected motor failures;
 5. physics: rigid-body step by dt in the wind; the new truth state (plus optional seeded noise) becomes the
    estimate (wind, noise, failures, battery and link watchdog: faults.py, once per commander cycle too);
 6. land detector on the new estimate (50 Hz, and at once when arming changes) -> commander ("Takeoff detected" /
    "Landing detected");
 7. events: the task's messages join the event stream; a mission's RTL item asks the commander for Return.
Commands (handle_command) and offboard inputs (offboard_input) act at once between steps, as PX4's commander acts
on a command in its next cycle (~10 ms, reference 11.6). Nothing here reads the wall clock.
"""

from __future__ import annotations

import itertools
from collections import deque
from typing import Final

from sitl_emu.commander.commander import Commander
from sitl_emu.commander.commands import handle_command
from sitl_emu.control.qmath import euler_from_q, yaw_from_q
from sitl_emu.disturbance.estimate import EstimateNoiseSettings
from sitl_emu.disturbance.wind import WindSettings
from sitl_emu.events.catalogue import Px4Event, to_px4_event
from sitl_emu.flight_tasks.follow_estimator import TargetFix
from sitl_emu.geo import SIH_HOME, GeoRef, global_to_ned, ned_to_global
from sitl_emu.navigator.mission_store import MissionStore
from sitl_emu.navigator.rally import ReturnDestination
from sitl_emu.navigator.setpoint import NavInput, SetpointType
from sitl_emu.params import ParamRegistry, default_registry
from sitl_emu.params.settings import sih_config
from sitl_emu.physics import RigidBodyState, SihConfig
from sitl_emu.physics import step as physics_step
from sitl_emu.px4 import AUTO_MODES, LandedState, MavCmd, NavState, Severity
from sitl_emu.types import (
    AttitudeSetpoint,
    CommandAck,
    FollowTargetSample,
    GroundTruth,
    HomePosition,
    ManualControlSetpoint,
    OffboardControlMode,
    TrajectorySetpoint,
    Vec3,
    Vec4,
    VehicleCommand,
    VehicleEvent,
    VehicleSnapshot,
)
from sitl_emu.vehicle.control_chain import ControlChain, published_setpoints
from sitl_emu.vehicle.faults import VehicleFaults
from sitl_emu.vehicle.fence import FenceChecks, rtl_destination

EVENT_HISTORY: Final = 1000
# PX4's commander cycles every 10 ms (COMMANDER_MONITORING_INTERVAL); here every 2 ticks
COMMANDER_PERIOD_US: Final = 8000


class Vehicle:
    """A PX4 SITL multicopter in simulated time. See the module docstring for the step order."""

    dt_us: int = 4000  # 250 Hz, SIH lockstep

    def __init__(self, *, params: ParamRegistry | None = None,
                 home: tuple[float, float, float] = SIH_HOME, seed: int = 0, sysid: int = 1,
                 ready_delay_s: float = 2.0, wind: WindSettings | None = None,
                 estimate_noise: EstimateNoiseSettings | None = None) -> None:
        """Boot disarmed in Hold on the ground at `home` (lat_deg, lon_deg, alt_amsl_m), the local frame's origin.

        `ready_delay_s` is the simulated estimator warm-up before arming is possible; `wind` (mean, turbulence, gusts)
        and `estimate_noise` (seeded white noise and bias walk on position, velocity, attitude, on the ground as in
        flight: disturbance/estimate.py) are off by default (faults.py).
        """
        self.params: ParamRegistry = params if params is not None else default_registry()
        self.sysid = sysid
        self._home_tuple = home
        self._seed = seed
        self._ready_delay_us = round(ready_delay_s * 1e6)
        self._wind_settings = wind
        self._estimate_noise = estimate_noise
        self._events: deque[VehicleEvent] = deque(maxlen=EVENT_HISTORY)
        self._seq = 0
        self._px4_events: deque[tuple[int, Px4Event]] = deque(maxlen=EVENT_HISTORY)
        self._px4_seq = 0
        self._boot()

    def _boot(self) -> None:
        self._snap: VehicleSnapshot | None = None
        self._time_us = 0
        self.ref = GeoRef(*self._home_tuple)
        self._state = RigidBodyState()
        self._estimate = self._state
        self._motor_commands: Vec4 = (0.0, 0.0, 0.0, 0.0)  # the mixer's output of the last tick
        self._sih = sih_config(self.params)
        self._sih_watch = self.params.changes.watch()  # params/changes.py
        self.commander = Commander(self.params, self._emit, self._ned_of, self._here, self._send_px4_event)
        self.chain = ControlChain(self.params)
        self._setpoint_type = SetpointType.NONE
        self._task_finished = False
        self._mission_finished = False  # the mission result's `finished` the commander last saw
        self._commander_last_us = -COMMANDER_PERIOD_US
        self._nav_fn = self._nav_input  # bound once: the executor is handed it every tick
        self._emit_fn = self._emit  # likewise, for the geofence work every commander cycle
        self._missions = MissionStore()  # in memory only: a reboot empties it (navigator/mission_store.py)
        self.faults = VehicleFaults(self.params, self.commander.fault_flags, self._emit, seed=self._seed,
                                    dt_s=self.dt_us * 1e-6, wind=self._wind_settings, noise=self._estimate_noise)
        self._fence = FenceChecks(self.params)  # the navigator's geofence check (fence.py)
        self.chain.executor.rtl_destination = self._rtl_destination
        self.chain.executor.rtl_avoid_path = self._rtl_avoid_path
        self.commander.mission_store = self._missions
        self.chain.executor.attach_missions(self._missions)

    # ---- time ---------------------------------------------------------------------------------------------------
    @property
    def time_us(self) -> int:
        """Simulated time since boot (us), starting at 0."""
        return self._time_us

    def step(self) -> None:
        """Advance exactly one physics tick (dt_us), in the fixed order of the module docstring."""
        c = self.commander
        if c.reboot_requested:
            self._boot()
            return
        now = self._time_us = self._time_us + self.dt_us
        self._snap = None
        if c.nav_commands:  # the navigator refuses targets outside the geofence (fence.py)
            self._fence.check_commands(c, self.ref, self._estimate.pos_ned_m, self._emit_fn)
        dt_s = self.dt_us * 1e-6
        if now - self._commander_last_us >= COMMANDER_PERIOD_US:
            self._commander_last_us = now
            self.faults.update(now, c.armed, self._estimate)
            c.observe(now, estimator_ready=now >= self._ready_delay_us, task_finished=self._task_finished)
            self._fence.step(now, self._missions, c, self._estimate.pos_ned_m, self._state.pos_ned_m, self.ref,
                             self._emit_fn)
            c.update(now)
        chain = self.chain
        out = chain.executor.update(c.nav_state, c.armed, now, self._nav_fn, c.nav_commands, self.ref, dt_s,
                                    c.manual.setpoint)
        self._setpoint_type, self._task_finished = out.setpoint_type, out.task_finished
        motors_armed = c.armed and c.nav_state is not NavState.TERMINATION
        faults = self.faults
        motors = chain.control_update(self._estimate, out, motors_armed, c.landed, now, dt_s)
        motors = self._motor_commands = faults.motors(motors)
        self._state = physics_step(self._state, motors, dt_s, self._sih_config(), faults.wind_at(now, self._state))
        self._estimate = faults.estimate(self._state, dt_s)
        detected = chain.land(self._estimate, c.armed, out, now)
        if detected is not None:
            c.on_land_detector(detected.landed, detected.maybe_landed)
        if out.messages:  # the task said something this tick
            for severity, text in out.messages:
                self._emit(severity, "navigator", text, True, True)
        wants_rtl = c.nav_state is NavState.AUTO_MISSION and chain.executor.take_mode_request() is NavState.AUTO_RTL
        finished = self._missions.finished
        if finished and not self._mission_finished:
            c.on_mission_finished()
        self._mission_finished = finished
        if wants_rtl:  # the mission's RTL item: navigator issue_command -> the commander handles NAV_RETURN_TO_LAUNCH
            handle_command(c, VehicleCommand(MavCmd.NAV_RETURN_TO_LAUNCH, from_external=False), now)

    def run_until(self, time_us: int) -> None:
        """Step until time_us is reached (no-op if already there)."""
        while self._time_us < time_us:
            self.step()

    def run_for(self, seconds: float) -> None:
        """Step for `seconds` of simulated time."""
        self.run_until(self._time_us + round(seconds * 1e6))

    def _nav_input(self) -> NavInput:
        """The navigator task's input, built only when a task runs (before physics: the estimate of this tick)."""
        return self.chain.nav_input(self._time_us, self._estimate, self.commander, self.ref)

    def _rtl_destination(self, nav: NavInput) -> ReturnDestination | None:
        return rtl_destination(nav.pos_ned_m, self.params, self._missions, self.commander, self.ref)

    def _rtl_avoid_path(self, nav: NavInput, destination_ned_m: Vec3) -> list[tuple[float, float]]:
        return self._fence.rtl_avoidance(nav.pos_ned_m, destination_ned_m, self.ref, self._emit)

    def _sih_config(self) -> SihConfig:
        if self._sih_watch.changed():
            self._sih = sih_config(self.params)
        return self._sih

    # ---- inputs -------------------------------------------------------------------------------------------------
    def handle_command(self, cmd: VehicleCommand) -> CommandAck | None:
        """Act on a command now; the ACK to send, or None where PX4 sends no ACK (ARM_DISARM param1 not 0/1)."""
        self._snap = None
        if cmd.command == MavCmd.INJECT_FAILURE:  # the failure injection manager (commander/failure_injection.py)
            return self.faults.inject(cmd, self._time_us)
        return handle_command(self.commander, cmd, self._time_us)

    def gcs_heartbeat(self) -> None:
        """A ground station's HEARTBEAT arrived (the COM_DL_LOSS_T data-link watchdog, faults.py)."""
        self.faults.gcs_heartbeat(self._time_us)

    def offboard_input(self, mode: OffboardControlMode, trajectory: TrajectorySetpoint | None = None,
                       attitude: AttitudeSetpoint | None = None) -> None:
        """An offboard message: refreshes the COM_OF_LOSS_T watchdog in any mode; setpoints are used in OFFBOARD."""
        self._snap = None
        self.commander.offboard_signal(self._time_us, mode)
        self.chain.executor.offboard(mode, trajectory, attitude)

    def manual_control_input(self, setpoint: ManualControlSetpoint) -> None:
        """A MAVLink joystick's sticks (MANUAL_CONTROL): the vehicle's manual input per COM_RC_IN_MODE, in any mode
        (commander/manual_control.py)."""
        self._snap = None
        self.commander.manual_control_signal(self._time_us, setpoint)

    def follow_target_input(self, sample: FollowTargetSample) -> None:
        """A FOLLOW_TARGET from the ground station (PX4's follow_target topic), for Follow Target's estimator."""
        pos = global_to_ned(self.ref, sample.lat_deg, sample.lon_deg, sample.alt_amsl_m)
        self.chain.executor.follow_target(TargetFix(sample.time_us, pos, sample.vel_ned_m_s))

    def report(self, severity: Severity, module: str, text: str, is_event: bool = True) -> None:
        """Log a text from outside the core (e.g. the MAVLink receiver) into the same event stream."""
        self._emit(severity, module, text, is_event, True)

    def mission_store(self) -> MissionStore:
        """The stored mission, geofence and rally plans (the mission protocol writes them, the navigator reads)."""
        return self._missions

    def reboot(self) -> None:
        """Back to the boot state now: time 0, disarmed in Hold, parameters kept (event seq keeps counting)."""
        self._boot()

    # ---- outputs ------------------------------------------------------------------------------------------------
    def events_after(self, seq: int) -> list[VehicleEvent]:
        """Events with seq > `seq` still in the history (the last ~1000)."""
        if seq >= self._seq or not self._events:
            return []  # the common case: a link polls every tick and nothing new happened
        start = max(0, seq + 1 - self._events[0].seq)  # seqs are consecutive, so this is the index
        return list(itertools.islice(self._events, start, None))

    @property
    def last_event_seq(self) -> int:
        return self._seq

    def px4_events_after(self, seq: int) -> list[tuple[int, Px4Event]]:
        """PX4's events (events/) with their own seq > `seq`, in the order sent: the one each text goes with and
        those the commander sends without a text (the failsafe notices' arguments, the health report)."""
        if seq >= self._px4_seq or not self._px4_events:
            return []
        start = max(0, seq + 1 - self._px4_events[0][0])
        return list(itertools.islice(self._px4_events, start, None))

    def _emit(self, severity: Severity, module: str, text: str, is_event: bool, statustext: bool) -> None:
        self._seq += 1
        event = VehicleEvent(self._seq, self._time_us, severity, module, text, is_event, statustext)
        self._events.append(event)
        px4 = to_px4_event(event)
        if px4 is not None:
            self._send_px4_event(px4)

    def _send_px4_event(self, event: Px4Event) -> None:
        self._px4_seq += 1
        self._px4_events.append((self._px4_seq, event))

    def _ned_of(self, lat_deg: float, lon_deg: float, alt_amsl_m: float) -> Vec3:
        return global_to_ned(self.ref, lat_deg, lon_deg, alt_amsl_m)

    def _here(self) -> HomePosition | None:
        if self._time_us < self._ready_delay_us:
            return None
        pos = self._estimate.pos_ned_m
        lat, lon, alt = ned_to_global(self.ref, pos)
        return HomePosition(lat, lon, alt, pos, yaw_from_q(self._estimate.q_wxyz))

    def landed_state(self) -> LandedState:
        """EXTENDED_SYS_STATE.landed_state (reference 5.5)."""
        c = self.commander
        if c.landed:
            return LandedState.ON_GROUND
        if c.nav_state in AUTO_MODES and self._setpoint_type is SetpointType.TAKEOFF:
            return LandedState.TAKEOFF
        if c.nav_state in AUTO_MODES and self._setpoint_type is SetpointType.LAND:
            return LandedState.LANDING
        return LandedState.IN_AIR

    def ground_truth(self) -> GroundTruth:
        """The physics' true state now, with its geodetic position (SIH's groundtruth topics; HIL_STATE_QUATERNION)."""
        s = self._state
        lat, lon, alt = ned_to_global(self.ref, s.pos_ned_m)
        return GroundTruth(s.pos_ned_m, s.vel_ned_m_s, s.acc_ned_m_s2, s.q_wxyz, s.rates_frd_rad_s, lat, lon, alt)

    @property
    def estimate(self) -> RigidBodyState:
        """The state estimate after the last step, read only: for readers of a few fields at high rate (the flight
        logger), who need no whole snapshot."""
        return self._estimate

    def position_valid(self) -> bool:
        """Whether the position estimate is valid (the snapshot's position_valid)."""
        c = self.commander
        return c.estimator_ready and not c.fault_flags.position_lost

    def snapshot(self) -> VehicleSnapshot:
        """Everything telemetry needs at the current simulated time (cached until the next step or input)."""
        if self._snap is None:
            self._snap = self._make_snapshot()
        return self._snap

    def _make_snapshot(self) -> VehicleSnapshot:
        c, s, ref = self.commander, self._estimate, self.ref
        lat, lon, alt = ned_to_global(ref, s.pos_ned_m)
        euler = euler_from_q(s.q_wxyz)
        offboard_last = c.offboard_mode_last
        local_sp, q_sp, rates_sp, thrust = published_setpoints(self.chain.control, c.nav_state, c.armed, offboard_last,
                                                               euler[2])
        return VehicleSnapshot(
            time_us=self._time_us, armed=c.armed, nav_state=c.nav_state,
            user_intended_nav_state=c.intention.user_intended, failsafe=c.failsafe, landed_state=self.landed_state(),
            pre_flight_checks_pass=c.pre_flight_checks_pass(),
            position_valid=self.position_valid(),
            takeoff_detected=c.have_taken_off, offboard_control=c.offboard_mode,
            pos_ned_m=s.pos_ned_m, vel_ned_m_s=s.vel_ned_m_s, acc_ned_m_s2=s.acc_ned_m_s2, q_wxyz=s.q_wxyz,
            rates_frd_rad_s=s.rates_frd_rad_s, euler_rad=euler, lat_deg=lat, lon_deg=lon,
            alt_amsl_m=alt, ref_lat_deg=ref.lat_deg, ref_lon_deg=ref.lon_deg, ref_alt_amsl_m=ref.alt_amsl_m,
            home=c.home, local_setpoint=local_sp, attitude_setpoint_q_wxyz=q_sp, rates_setpoint_rad_s=rates_sp,
            thrust_setpoint=thrust, motors=self._state.motors, extras={"system_status": float(c.system_status())},
            motor_commands=self._motor_commands, offboard_control_last=offboard_last,
            manual_control=c.manual_control_valid(self._time_us), orbit=self.chain.executor.orbit_status(ref),
            battery_voltage_v=self.faults.battery.voltage_v, battery_remaining=self.faults.battery.remaining,
            battery_warning=self.faults.battery.warning, gps_fix_type=self.faults.gps_fix_type,
        )
