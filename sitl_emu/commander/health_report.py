"""PX4's health and arming check report (src/modules/commander/HealthAndArmingChecks: Common.cpp Report,
HealthAndArmingChecks.cpp update, checks/modeCheck.cpp, geofenceCheck.cpp, rcAndDataLinkCheck.cpp), as events.

`health_report` runs the checks the emulator models on what the commander sees and returns the report: the failing
checks (event, modes affected, health component, log level), the arming checks' error and warning components, and
can_arm / can_run as one bit per nav_state (Report::getModeGroup: group == mode). Each failing check clears the bits
of the modes it requires (armingCheckFailure -> clearArmingBits, the mode checks' clearCanRunBits), with the modes
the emulator's own requirement table gives (commander/arming.py), so the report says what the commander does.

`HealthReporter` decides when the checks run (Commander::run: every 100 ms, and at once when the mode or the arming
state changed) and when a report goes out (Report::report): when it differs from the one before, at most once per
2 s (a change inside that window goes out when it ends), and at once when forced (MAV_CMD_RUN_PREARM_CHECKS).
Health: the components PX4 SIH has are present (as SYS_STATUS reports them, mavlink/telemetry/health.py), the
remote control while manual control is valid, the communication links while the ground station is not lost.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

from sitl_emu.commander.arming import CheckInputs, Req, modes_requiring
from sitl_emu.commander.battery import WARNING_CRITICAL, WARNING_EMERGENCY, WARNING_LOW, WARNING_NONE
from sitl_emu.commander.fault_failsafes import FaultFlags
from sitl_emu.events import health_events as ev
from sitl_emu.events.definition import EventDefinition, Px4Event, px4_event
from sitl_emu.events.enums import health_component_index
from sitl_emu.events.library import Log, log_levels
from sitl_emu.navigator.geofence import GeofenceResult
from sitl_emu.px4 import NavState

ALL_MODES: Final = 0xFFFFFFFF
NO_MODES: Final = 0
MIN_REPORTING_INTERVAL_US: Final = 2_000_000
CHECK_INTERVAL_US: Final = 100_000
SYSTEM: Final = health_component_index("system")
REMOTE_CONTROL: Final = health_component_index("remote_control")
BATTERY: Final = health_component_index("battery")
COMMUNICATION_LINKS: Final = health_component_index("communication_links")
_SIH_PRESENT: Final = sum(1 << health_component_index(n) for n in (
    "gyro", "accel", "magnetometer", "absolute_pressure", "gps", "local_position_estimate", "motors_escs", "logging",
    "battery"))


@dataclass(frozen=True, slots=True)
class FailedCheck:
    event: EventDefinition
    modes: int  # navigation_mode_group_t: the modes it affects (all when it blocks none)
    component: int  # the health component's bit number
    level: Log


@dataclass(frozen=True, slots=True)
class HealthReport:
    checks: tuple[FailedCheck, ...]
    arming_error: int  # health_component_t bits
    arming_warning: int
    can_arm: int  # navigation_mode_group_t bits
    can_run: int
    present: int
    health_error: int = 0
    health_warning: int = 0

    def can_arm_in(self, nav_state: NavState) -> bool:
        return bool(self.can_arm >> int(nav_state) & 1)


@dataclass(slots=True)
class ReportInputs:
    """What the checks look at (compared with the last: the report is only rebuilt when it changes); made every
    100 ms, so not frozen, its `__init__` written out (ARCHITECTURE.md, On the tick path); read-only by convention."""

    nav_state: NavState
    armed: bool
    missing: int  # the Req bits the commander's CheckInputs do not satisfy (failsafe_flags' invalid bits)
    geofence: GeofenceResult
    gcs_lost: bool
    battery_warning: int  # battery_status WARNING_*
    manual_control: bool
    stick_input_disabled: bool  # COM_RC_IN_MODE 4
    datalink_required: bool  # NAV_DLL_ACT > 0
    mission_required: bool = False  # COM_ARM_MIS_REQ

    def __init__(self, nav_state: NavState, armed: bool, missing: int, geofence: GeofenceResult, gcs_lost: bool,
                 battery_warning: int, manual_control: bool, stick_input_disabled: bool,
                 datalink_required: bool, mission_required: bool = False) -> None:
        self.nav_state = nav_state
        self.armed = armed
        self.missing = missing
        self.geofence = geofence
        self.gcs_lost = gcs_lost
        self.battery_warning = battery_warning
        self.manual_control = manual_control
        self.stick_input_disabled = stick_input_disabled
        self.datalink_required = datalink_required
        self.mission_required = mission_required

    def __eq__(self, other: object) -> bool:
        """The dataclass's comparison, field by field, written out so that mypyc compiles it (the generated one
        stays interpreted; the reporter compares every 100 ms)."""
        if not isinstance(other, ReportInputs):
            return NotImplemented
        return (self.nav_state is other.nav_state and self.armed == other.armed
                and self.missing == other.missing and self.geofence == other.geofence
                and self.gcs_lost == other.gcs_lost and self.battery_warning == other.battery_warning
                and self.manual_control == other.manual_control
                and self.stick_input_disabled == other.stick_input_disabled
                and self.datalink_required == other.datalink_required
                and self.mission_required == other.mission_required)

    @staticmethod
    def of(nav_state: NavState, armed: bool, c: CheckInputs, geofence: GeofenceResult, faults: FaultFlags,
           stick_input_disabled: bool, datalink_required: bool) -> ReportInputs:
        # the class by name, not a classmethod's `cls`: compiled, that is a call through Python's type call
        return ReportInputs(nav_state, armed, _CHECKED & ~c.available(), geofence,
                            faults.gcs_connection_lost, faults.battery_warning, c.manual_control,
                            stick_input_disabled, datalink_required, c.mission_required)


class _Builder:
    """Report's results while the checks run: failures clear can_arm / can_run bits."""

    def __init__(self) -> None:
        self.checks: list[FailedCheck] = []
        self.error = self.warning = 0
        self.can_arm = self.can_run = ALL_MODES

    def fail(self, event: EventDefinition, modes: int, component: int = SYSTEM, level: Log | None = None,
             clear_run: bool = True) -> None:
        """armingCheckFailure(modes, component, event, level) (+ clearCanRunBits(modes) for the mode checks)."""
        level = event.external if level is None else level
        if level <= Log.ERROR:
            self.error |= 1 << component
        elif level <= Log.WARNING:
            self.warning |= 1 << component
        self.can_arm &= ~modes
        if clear_run:
            self.can_run &= ~modes
        self.checks.append(FailedCheck(event, modes or ALL_MODES, component, level))


def health_report(i: ReportInputs) -> HealthReport:
    b = _Builder()
    _battery_check(b, i.battery_warning)
    _geofence_checks(b, i.geofence)
    if i.gcs_lost:  # rcAndDataLinkCheck.cpp
        b.fail(ev.NO_DATALINK, ALL_MODES if i.datalink_required else NO_MODES, COMMUNICATION_LINKS,
               Log.ERROR if i.datalink_required else Log.INFO, clear_run=False)
    _mode_checks(b, i)
    present = _SIH_PRESENT | (0 if i.gcs_lost else 1 << COMMUNICATION_LINKS)
    if i.manual_control:
        present |= 1 << REMOTE_CONTROL
    return HealthReport(tuple(b.checks), b.error, b.warning, b.can_arm & ALL_MODES, b.can_run & ALL_MODES, present)


_BATTERY_CHECKS: Final = {WARNING_LOW: ev.BATTERY_LOW, WARNING_CRITICAL: ev.BATTERY_CRITICAL,
                           WARNING_EMERGENCY: ev.BATTERY_EMERGENCY}


def _battery_check(b: _Builder, warning: int) -> None:
    """batteryCheck.cpp: a warning level fails arming in every mode from critical on (COM_ARM_BAT_MIN at its
    default -1 adds no threshold of its own); a low level is a warning only. Disarmed the simulated battery is full."""
    if warning == WARNING_NONE or warning not in _BATTERY_CHECKS:
        return
    critical = warning >= WARNING_CRITICAL
    b.fail(_BATTERY_CHECKS[warning], ALL_MODES if critical else NO_MODES, BATTERY,
           Log.CRITICAL if critical else Log.WARNING, clear_run=False)


def _geofence_checks(b: _Builder, g: GeofenceResult) -> None:
    """geofenceCheck.cpp: each limit crossed (GF_ACTION not None) fails arming in every mode."""
    if not g.breached:
        return
    for crossed, event in ((g.max_dist, ev.GEOFENCE_MAX_DISTANCE), (g.max_alt, ev.GEOFENCE_MAX_ALTITUDE),
                           (g.custom, ev.GEOFENCE_CUSTOM)):
        if crossed:
            b.fail(event, ALL_MODES, clear_run=False)


# modeCheck.cpp's checks after "Mode not suitable for arming", in its order: the requirements each one looks at, its
# event. Each clears the arming and can-run bits of the modes requiring what it misses. The angular velocity check
# is left out: the simulated gyro never stops.
_MODE_CHECKS: Final = (
    (Req.ATTITUDE, ev.ATTITUDE),
    (Req.LOCAL_POSITION | Req.LOCAL_POSITION_RELAXED, ev.LOCAL_POSITION),
    (Req.GLOBAL_POSITION, ev.GLOBAL_POSITION),
    (Req.LOCAL_ALT, ev.LOCAL_ALTITUDE),
    (Req.MISSION, ev.MISSION),
    (Req.OFFBOARD, ev.OFFBOARD_SIGNAL),
    (Req.HOME, ev.HOME_POSITION),
)
_CHECKED: Final = Req.MANUAL | sum(req for req, _ in _MODE_CHECKS)


def _mode_checks(b: _Builder, i: ReportInputs) -> None:
    """modeCheck.cpp, in its order: the mode prevents arming (disarmed only), then each requirement not met, with
    the modes that require it (mode_requirements.cpp, as commander/arming.py holds them; a missing mission with
    COM_ARM_MIS_REQ 1 fails arming in every mode)."""
    prevent = modes_requiring(Req.PREVENT_ARMING)
    if not i.armed and prevent >> int(i.nav_state) & 1:
        b.fail(ev.CANNOT_TAKEOFF, prevent, clear_run=False)
    for req, event in _MODE_CHECKS:
        if not i.missing & req:
            continue
        modes = modes_requiring(i.missing & req)
        if req == Req.MISSION and i.mission_required:  # COM_ARM_MIS_REQ: no arming in any mode, Mission cannot run
            b.fail(event, ALL_MODES, clear_run=False)
            b.can_run &= ~modes
        else:
            b.fail(event, modes)
    if i.missing & Req.MANUAL:
        manual = modes_requiring(Req.MANUAL)
        disabled = i.stick_input_disabled
        b.fail(ev.MANUAL_CONTROL, manual if disabled else NO_MODES, REMOTE_CONTROL,
               Log.ERROR if disabled else Log.WARNING)
        b.can_arm &= ~manual
        b.can_run &= ~manual


class HealthReporter:
    """Report::report: which reports go out, and the events of one."""

    def __init__(self) -> None:
        self._inputs: ReportInputs | None = None
        self.report: HealthReport | None = None
        self._last_report_us = 0
        self._unreported = False
        self._last_check_us: int | None = None
        self._nav_state: NavState | None = None  # the status at the last run
        self._armed = False

    def due(self, now_us: int, nav_state: NavState, armed: bool, force: bool = False) -> bool:
        """Whether the checks run now: 100 ms after the last run, when the mode or arming changed, or forced."""
        if force or nav_state is not self._nav_state or armed != self._armed or self._last_check_us is None \
                or now_us >= self._last_check_us + CHECK_INTERVAL_US:
            self._last_check_us, self._nav_state, self._armed = now_us, nav_state, armed
            return True
        return False

    def update(self, now_us: int, inputs: ReportInputs, force: bool = False) -> list[Px4Event]:
        """Run the checks (again only if their inputs changed); the events to send now, if a report is due."""
        changed = False
        if inputs != self._inputs:
            self._inputs = inputs
            report = health_report(inputs)
            changed, self.report = report != self.report, report
        assert self.report is not None
        if now_us < self._last_report_us + MIN_REPORTING_INTERVAL_US and not force:
            self._unreported = self._unreported or changed
            return []
        if not (changed or self._unreported or force):
            return []
        self._last_report_us, self._unreported = now_us, False
        return report_events(self.report, now_us)


def report_events(r: HealthReport, now_us: int) -> list[Px4Event]:
    """The arming check summary, each failing check, the health summary (chunk 0)."""
    events = [px4_event(ev.ARMING_CHECK_SUMMARY, (0, r.arming_error, r.arming_warning, r.can_arm, r.can_run), now_us)]
    events += [px4_event(c.event, (c.modes, c.component), now_us, log_levels(c.level)) for c in r.checks]
    events.append(px4_event(ev.HEALTH_SUMMARY, (0, r.present, r.health_error, r.health_warning), now_us))
    return events
