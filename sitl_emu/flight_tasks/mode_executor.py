"""Which setpoint drives the controllers: the navigator task of the mode in force, or the offboard stream.

PX4 splits this between navigator (navigator_main.cpp: one task per nav_state, vehicle_command parameters for
takeoff/reposition) and flight_mode_manager; here it is one small object. Rules:
- a new task starts when the mode in force changes, at arming, and when a command brings new navigator parameters;
  no task runs while disarmed (navigator_main.cpp);
- Takeoff -> Hold after the takeoff finished holds at the takeoff target (navigator converts the takeoff item into a
  loiter there, Commander.cpp ~l.2208, loiter.cpp ~l.54-136); so does Hold after a finished mission at the
  mission's last setpoint (Commander::checkForMissionUpdate, can_loiter_at_sp);
- OFFBOARD uses the latest offboard setpoint (trajectory for position/velocity/acceleration, else attitude/rates);
- POSCTL and ALTCTL run the manual flight tasks (flight_tasks/manual.py) on the latest sticks; STABILIZED and
  MANUAL turn the sticks into an attitude and thrust every tick (flight_tasks/stabilized.py); termination has no
  setpoint (the motors stop).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Final

from sitl_emu.commander.manual_control import CENTRED
from sitl_emu.control.qmath import isfinite
from sitl_emu.flight_tasks import auto, orbit
from sitl_emu.flight_tasks.core import AutoSettings
from sitl_emu.flight_tasks.follow import FollowTargetTask
from sitl_emu.flight_tasks.follow_estimator import TargetFix
from sitl_emu.flight_tasks.manual import ManualAltitudeTask, ManualPositionTask
from sitl_emu.flight_tasks.mission import MissionFlight, MissionTask
from sitl_emu.flight_tasks.rtl_mission import (
    RTL_CHECK_PERIOD_US,
    MissionLandAltitude,
    MissionReturn,
    RtlMissionTask,
    mission_return,
)
from sitl_emu.flight_tasks.stabilized import StabilizedMode
from sitl_emu.geo import GeoRef, global_to_ned
from sitl_emu.navigator.commands import NavCommand, NavCommandKind
from sitl_emu.navigator.mission_store import MissionStore
from sitl_emu.navigator.rally import ReturnDestination
from sitl_emu.navigator.setpoint import SetpointType
from sitl_emu.params import ParamRegistry
from sitl_emu.px4 import NavState, Severity
from sitl_emu.types import (
    AttitudeSetpoint,
    ManualControlSetpoint,
    OffboardControlMode,
    OrbitStatus,
    TrajectorySetpoint,
    Vec3,
)

_TASK_MODES: Final = frozenset({NavState.AUTO_LOITER, NavState.AUTO_TAKEOFF, NavState.AUTO_LAND, NavState.DESCEND,
                                NavState.AUTO_RTL, NavState.POSCTL, NavState.POSITION_SLOW, NavState.ALTCTL,
                                NavState.AUTO_MISSION, NavState.ORBIT, NavState.AUTO_FOLLOW_TARGET})
_STICK_ATTITUDE_MODES: Final = frozenset({NavState.STAB, NavState.MANUAL})
# the modes flight_mode_manager flies with FlightTaskAuto (FlightModeManager::start_flight_task): one after another
# the task runs on, so the heading setpoint carries over
_FLIGHT_TASK_AUTO: Final = frozenset({NavState.AUTO_TAKEOFF, NavState.AUTO_LOITER, NavState.AUTO_MISSION,
                                      NavState.AUTO_RTL, NavState.AUTO_LAND})
FlightTask = auto.Task | ManualAltitudeTask | orbit.FailedOrbitHold | FollowTargetTask
# the tasks that read the sticks: a tuple, as `A | B` in isinstance builds a union object at every check
_STICK_TASKS: Final = (ManualAltitudeTask, FollowTargetTask)


@dataclass(slots=True)
class ExecutorOutput:
    """What the mode in force asks of the controllers this tick; read-only by convention (see ARCHITECTURE.md, On
    the tick path)."""

    trajectory: TrajectorySetpoint | None
    attitude: AttitudeSetpoint | None
    setpoint_type: SetpointType
    task_finished: bool
    messages: Sequence[tuple[Severity, str]]
    want_takeoff: bool | None = None  # the task's vehicle_constraints.want_takeoff; None: from the setpoint

    def __init__(self, trajectory: TrajectorySetpoint | None, attitude: AttitudeSetpoint | None,
                 setpoint_type: SetpointType, task_finished: bool, messages: Sequence[tuple[Severity, str]],
                 want_takeoff: bool | None = None) -> None:
        self.trajectory = trajectory
        self.attitude = attitude
        self.setpoint_type = setpoint_type
        self.task_finished = task_finished
        self.messages = messages
        self.want_takeoff = want_takeoff


_NO_SETPOINT: Final = ExecutorOutput(None, None, SetpointType.NONE, False, ())


class ModeExecutor:
    """Owns the current navigator task and the latest offboard setpoints."""

    def __init__(self, params: ParamRegistry) -> None:
        self.params = params
        self.task: FlightTask | None = None
        self._stabilized: StabilizedMode | None = None  # STABILIZED / MANUAL, while in force
        self._task_mode: NavState | None = None  # the mode self.task flies; None exactly when no task runs
        self._pending_takeoff: NavCommand | None = None  # NAV_TAKEOFF parameters, used when the takeoff starts
        self._offboard_kind: OffboardControlMode | None = None
        self._offboard_traj: TrajectorySetpoint | None = None
        self._offboard_att: AttitudeSetpoint | None = None
        self._offboard_out: ExecutorOutput | None = None  # built from the offboard inputs when they change
        self._held: ExecutorOutput | None = None  # the task's last output, reused until task.period_us has passed
        self._last_us = 0  # when the task last ran
        self._next_us = 0  # when it runs again: _last_us + its period_us (read once a run, not every tick)
        # where Return goes when not home (a rally point: NED position, yaw), asked as RTL starts; the vehicle sets it
        self.rtl_destination: Callable[[auto.NavInput], ReturnDestination | None] | None = None
        # the geofence avoidance waypoints (north, east) from the vehicle to a return destination; the vehicle sets it
        self.rtl_avoid_path: Callable[[auto.NavInput, Vec3], list[tuple[float, float]]] | None = None
        self.missions: MissionFlight | None = None  # AUTO.MISSION's navigator over the stored plans (attach_missions)
        self._target_fix: TargetFix | None = None  # the latest FOLLOW_TARGET, for Follow Target
        self._mission_land = MissionLandAltitude()  # the mission landing's return altitude (RTL_TYPE 1 and 3)
        self._rtl_check_us = 0  # when Return's destination is evaluated next while Return is inactive
        self._auto_settings: AutoSettings | None = None  # for that evaluation, read again when a parameter changes
        self._auto_watch = params.changes.watch(current=False)  # params/changes.py

    def attach_missions(self, store: MissionStore) -> None:
        """The stored plans AUTO.MISSION flies (the Vehicle's store; the navigator state lives as long as it)."""
        self.missions = MissionFlight(store)

    def take_mode_request(self) -> NavState | None:
        """A mode the running task asks the commander for (the mission's RTL item: Return), once."""
        task = self.task
        if isinstance(task, MissionTask) and task.wants_rtl:
            return NavState.AUTO_RTL
        return None

    def offboard(self, mode: OffboardControlMode, trajectory: TrajectorySetpoint | None,
                 attitude: AttitudeSetpoint | None) -> None:
        self._offboard_kind = mode
        if trajectory is not None:
            self._offboard_traj = trajectory
        if attitude is not None:
            self._offboard_att = attitude
        self._offboard_out = None

    def follow_target(self, fix: TargetFix) -> None:
        """A FOLLOW_TARGET (in the local frame): the follow-target estimator reads the latest when it runs."""
        self._target_fix = fix
        if isinstance(self.task, FollowTargetTask):
            self.task.fix = fix

    def update(self, nav_state: NavState, armed: bool, now_us: int, nav_fn: Callable[[], auto.NavInput],
               commands: list[NavCommand], ref: GeoRef, dt_s: float,
               sticks: ManualControlSetpoint = CENTRED) -> ExecutorOutput:
        """This tick's setpoint; `nav_fn` builds the task input (called only when a task runs or starts); `sticks`
        is the last manual input (the commander's, commander/manual_control.py), for the manual modes."""
        if now_us >= self._rtl_check_us and nav_state is not NavState.AUTO_RTL:
            self._rtl_check_us = now_us + RTL_CHECK_PERIOD_US
            self._check_rtl_destination(nav_fn())
        new_task = self._select_task(nav_state, armed, nav_fn, commands, ref)
        if self._task_mode is None and nav_state in _STICK_ATTITUDE_MODES:  # a task runs only in a task mode
            return self._stick_attitude(armed, nav_fn, dt_s, sticks)
        self._stabilized = None
        if nav_state is NavState.OFFBOARD:
            if self._offboard_out is None:
                self._offboard_out = self._offboard_output()
            return self._offboard_out
        if self.task is None:
            return _NO_SETPOINT
        return self._run_task(self.task, now_us, nav_fn, dt_s, new_task, sticks)

    def _stick_attitude(self, armed: bool, nav_fn: Callable[[], auto.NavInput], dt_s: float,
                        sticks: ManualControlSetpoint) -> ExecutorOutput:
        """STABILIZED / MANUAL: the sticks' attitude and thrust, every tick (mc_att_control)."""
        if not armed:
            self._stabilized = None
            return _NO_SETPOINT
        nav = nav_fn()
        if self._stabilized is None:
            self._stabilized = StabilizedMode(nav, self.params)
        self._stabilized.sticks = sticks
        return ExecutorOutput(None, self._stabilized.update(nav, dt_s), SetpointType.NONE, False, ())

    def _run_task(self, task: FlightTask, now_us: int, nav_fn: Callable[[], auto.NavInput], dt_s: float,
                  new_task: bool, sticks: ManualControlSetpoint) -> ExecutorOutput:
        """The task's setpoint, computed every task.period_us (the last one is held in between)."""
        held = self._held
        dt = dt_s
        if held is not None and not new_task:
            if now_us < self._next_us:
                return held
            dt = (now_us - self._last_us) * 1e-6
        # the auto tasks' compiled class first: a native type check, where the tuple of interpreted classes costs two
        # __instancecheck__ look-ups every task cycle
        if not isinstance(task, auto.Task) and isinstance(task, _STICK_TASKS):
            task.sticks = sticks
        sp = task.update(nav_fn(), dt)
        held = self._held = ExecutorOutput(sp, None, task.setpoint_type, task.finished, (), task.want_takeoff)
        self._last_us, self._next_us = now_us, now_us + task.period_us
        messages = task.drain_messages()
        if not messages:
            return held
        return ExecutorOutput(sp, None, held.setpoint_type, held.task_finished, messages, held.want_takeoff)

    def _offboard_output(self) -> ExecutorOutput:
        kind = self._offboard_kind
        use_traj = kind is not None and (kind.position or kind.velocity or kind.acceleration)
        if use_traj or self._offboard_att is None:
            return ExecutorOutput(self._offboard_traj, None, SetpointType.OFFBOARD, False, ())
        return ExecutorOutput(None, self._offboard_att, SetpointType.OFFBOARD, False, ())

    # ---- task selection -----------------------------------------------------------------------------------------
    def _select_task(self, nav_state: NavState, armed: bool, nav_fn: Callable[[], auto.NavInput],
                     commands: list[NavCommand], ref: GeoRef) -> bool:
        """Start the task the mode (or a command) asks for; True if a new task started.

        navigator_main.cpp runs no mode while disarmed ("Do not execute any state machine while we are disarmed"):
        the task starts at arming, with the parameters of a NAV_TAKEOFF received before."""
        command = self._take_commands(commands) if commands else None
        # the running task's mode is a task mode: the set look-up only when the mode changed
        if not armed or (nav_state is not self._task_mode and nav_state not in _TASK_MODES):
            self.task, self._task_mode, self._held = None, None, None
            if nav_state is not NavState.AUTO_TAKEOFF:
                self._pending_takeoff = None
            return False
        new_takeoff = self._pending_takeoff is not None and nav_state is NavState.AUTO_TAKEOFF
        if nav_state is self._task_mode and command is None and not new_takeoff:
            return False  # the running task still fits
        if nav_state is NavState.ORBIT and self._task_mode is NavState.ORBIT and command is not None:
            self.task = self._orbit(nav_fn(), command, ref)  # the running orbit takes the new parameters
            return True
        self._start_task(nav_state, nav_fn(), command, ref)
        return True

    def _take_commands(self, commands: list[NavCommand]) -> NavCommand | None:
        """Empty the commander's (non-empty) queue: a NAV_TAKEOFF waits for the takeoff to start; the last command is
        returned unless it is a NAV_TAKEOFF (a reposition or altitude change restarts Hold)."""
        for cmd in commands:
            if cmd.kind is NavCommandKind.TAKEOFF:
                self._pending_takeoff = cmd
        last = commands[-1]
        commands.clear()
        return None if last.kind is NavCommandKind.TAKEOFF else last

    def _start_task(self, nav_state: NavState, nav: auto.NavInput, command: NavCommand | None, ref: GeoRef) -> None:
        takeoff_target: Vec3 | None = None  # Hold after a finished takeoff or mission holds at its last target
        if self._task_mode is NavState.AUTO_TAKEOFF and self.task is not None and self.task.finished:
            takeoff_target = getattr(self.task, "target_ned_m", None)
        elif isinstance(self.task, MissionTask):
            takeoff_target = self.task.end_loiter_point()
        previous, previous_mode = self.task, self._task_mode
        self._task_mode = nav_state
        self._make_task(nav_state, nav, command, ref, takeoff_target)
        if (previous_mode in _FLIGHT_TASK_AUTO and nav_state in _FLIGHT_TASK_AUTO
                and isinstance(previous, auto.Task) and isinstance(self.task, auto.Task)):
            self.task.continue_heading(previous)

    def _make_task(self, nav_state: NavState, nav: auto.NavInput, command: NavCommand | None, ref: GeoRef,
                   takeoff_target: Vec3 | None) -> None:
        if nav_state is NavState.AUTO_TAKEOFF:
            self.task = self._make_takeoff(nav, self._pending_takeoff, ref)
            self._pending_takeoff = None
        elif nav_state is NavState.AUTO_LOITER:
            self.task = self._make_loiter(nav, command, ref, takeoff_target)
        elif nav_state is NavState.AUTO_RTL:
            self.task = self._make_rtl(nav, ref)
        elif nav_state is NavState.AUTO_MISSION:
            self.task = self._make_mission(nav, ref)
        elif nav_state in (NavState.POSCTL, NavState.POSITION_SLOW):
            self.task = ManualPositionTask(nav, self.params, self._last_setpoint())
        elif nav_state is NavState.ALTCTL:
            self.task = ManualAltitudeTask(nav, self.params, self._last_setpoint())
        elif nav_state is NavState.ORBIT:
            self.task = self._orbit(nav, command, ref)
        elif nav_state is NavState.AUTO_FOLLOW_TARGET:
            self.task = follow = FollowTargetTask(nav, self.params)
            follow.fix = self._target_fix
        else:
            self.task = auto.make_land(nav, self.params)

    def _last_setpoint(self) -> TrajectorySetpoint | None:
        """The setpoint the previous task gave last (FlightModeManager::switchTask hands it to the new task's
        activate()); None after a mode without a flight task."""
        return self._held.trajectory if self._held is not None else None

    def _make_rtl(self, nav: auto.NavInput, ref: GeoRef) -> auto.Task:
        """Return as RTL_TYPE says (flight_tasks/rtl_mission.py): along the mission, else directly to home
        or the destination the vehicle chose. Read before self.task is replaced: the mission's current item when
        AUTO.MISSION ran just before (RtlMissionFastReverse::on_inactive)."""
        missions = self.missions
        way = mission_return(int(self.params.get("RTL_TYPE")), missions.store) if missions is not None else None
        if missions is not None and way is not None:
            prior_seq = missions.store.current_seq if isinstance(self.task, MissionTask) else -1
            home_alt = ref.alt_amsl_m - nav.home_ned_m[2]
            return RtlMissionTask(nav, self.params, missions.store, ref, home_alt, way, prior_seq)
        destination = self._check_rtl_destination(nav)
        if missions is not None and destination is not None and destination.mission_land:
            home_alt = ref.alt_amsl_m - nav.home_ned_m[2]
            return RtlMissionTask(nav, self.params, missions.store, ref, home_alt, MissionReturn.LAND, -1,
                                  self._mission_land.rtl_up_m)
        target = destination.pos_ned_m if destination is not None else nav.home_ned_m
        path = self.rtl_avoid_path(nav, target) if self.rtl_avoid_path else []
        where = (destination.pos_ned_m, destination.yaw_rad) if destination is not None else None
        return auto.make_rtl(nav, self.params, where, self._mission_loiter(nav), path)

    def _check_rtl_destination(self, nav: auto.NavInput) -> ReturnDestination | None:
        """RTL::setRtlTypeAndDestination: the destination (the vehicle's choice), the mission landing's altitude."""
        destination = self.rtl_destination(nav) if self.rtl_destination else None
        if self._auto_watch.changed() or self._auto_settings is None:
            self._auto_settings = AutoSettings.from_params(self.params)
        self._mission_land.evaluate(destination, nav, self._auto_settings)
        return destination

    def _mission_loiter(self, nav: auto.NavInput) -> Vec3 | None:
        """The loiter a finished mission left, if the vehicle is established on it (within NAV_ACC_RAD plus
        NAV_LOITER_RAD: navigator_main.cpp is_established_on_loiter), for RTL's climb."""
        task = self.task
        if not isinstance(task, MissionTask):
            return None
        return task.loiter_point(nav)

    def _make_mission(self, nav: auto.NavInput, ref: GeoRef) -> auto.Task:
        if self.missions is None:
            self.missions = MissionFlight(MissionStore())
        return MissionTask(nav, self.params, self.missions, ref, ref.alt_amsl_m - nav.home_ned_m[2])
    def _orbit(self, nav: auto.NavInput, command: NavCommand | None, ref: GeoRef) -> FlightTask:
        """The orbit flight task with a DO_ORBIT applied (orbit.apply_orbit)."""
        task = self.task if isinstance(self.task, orbit.OrbitFlight) else None
        do_orbit = command if command is not None and command.kind is NavCommandKind.ORBIT else None
        return orbit.apply_orbit(task if self._task_mode is NavState.ORBIT else None, do_orbit, nav, self.params, ref)

    def orbit_status(self, ref: GeoRef) -> OrbitStatus | None:
        """orbit_status while the orbit flight task runs (ORBIT_EXECUTION_STATUS), else None."""
        task = self.task
        return task.status(ref) if isinstance(task, orbit.OrbitTask) else None

    def _make_takeoff(self, nav: auto.NavInput, command: NavCommand | None, ref: GeoRef) -> auto.Task:
        alt_up: float | None = None
        if command is not None and command.kind is NavCommandKind.TAKEOFF and isfinite(command.alt_amsl_m):
            alt_up = command.alt_amsl_m - ref.alt_amsl_m  # param7 is AMSL; the local origin is at ref altitude
        return auto.make_takeoff(nav, self.params, alt_up)

    def _make_loiter(self, nav: auto.NavInput, command: NavCommand | None, ref: GeoRef,
                     takeoff_target: Vec3 | None) -> auto.Task:
        moves = (NavCommandKind.REPOSITION, NavCommandKind.CHANGE_ALTITUDE)
        if command is not None and command.kind in moves and nav.armed:
            target = _command_target(command, nav, ref)
            speed = command.speed_m_s if isfinite(command.speed_m_s) and command.speed_m_s > 0 else math.nan
            # DO_REPOSITION with yaw NaN: PX4 passes NaN on and the vehicle faces the target (MPC_YAW_MODE 0,
            # navigator_main.cpp); a change of altitude keeps the current heading.
            keep = nav.yaw_rad if command.kind is NavCommandKind.CHANGE_ALTITUDE else math.nan
            yaw = command.yaw_rad if isfinite(command.yaw_rad) else keep
            return auto.make_reposition(nav, self.params, target, yaw, speed)
        if takeoff_target is not None:
            return auto.make_loiter(nav, self.params, hold_at_ned_m=takeoff_target)
        return auto.make_loiter(nav, self.params)


def _command_target(command: NavCommand, nav: auto.NavInput, ref: GeoRef) -> Vec3:
    """The reposition target in NED; NaN lat/lon/alt keep the current position's component."""
    x, y, z = nav.pos_ned_m
    if isfinite(command.lat_deg) and isfinite(command.lon_deg):
        x, y, _ = global_to_ned(ref, command.lat_deg, command.lon_deg, ref.alt_amsl_m)
    if isfinite(command.alt_amsl_m):
        z = ref.alt_amsl_m - command.alt_amsl_m
    return x, y, z
