"""Commander's vehicle_command handling: MAV_CMD numbers in, ACK results and PX4's texts out.

After src/modules/commander/Commander.cpp handle_command (v1.15-v1.17 variants where versions differ); see
../shared/reference/px4-behaviour.md section 3 for every code and text. `None` means PX4 sends no ACK.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from sitl_emu.commander.commander import Commander
from sitl_emu.control.qmath import isfinite
from sitl_emu.navigator.commands import NavCommand, NavCommandKind
from sitl_emu.px4 import (
    MODE_FLAG_AUTO_ENABLED,
    MODE_FLAG_CUSTOM_MODE_ENABLED,
    MODE_FLAG_GUIDED_ENABLED,
    MODE_FLAG_MANUAL_INPUT_ENABLED,
    MODE_FLAG_STABILIZE_ENABLED,
    MainMode,
    MavCmd,
    MavFrame,
    MavResult,
    NavState,
    Severity,
    nav_state_from_main_sub,
)
from sitl_emu.types import CommandAck, VehicleCommand

FORCE_MAGIC = 21196  # param2 of ARM_DISARM that forces (Commander.cpp)
MISSION_PLANNER_COMPID = 190  # MAV_COMP_ID_MISSIONPLANNER: only it gets "Switching to ... not available"
REPOSITION_FLAG_CHANGE_MODE = 1  # MAV_DO_REPOSITION_FLAGS_CHANGE_MODE


def lround(x: float) -> int:
    """C lroundf: halves away from zero (Python's round() rounds halves to even). x must be finite."""
    return int(math.copysign(math.floor(abs(x) + 0.5), x))


def _uint8(x: float) -> int:
    """(uint8_t)float as the MAVLink receiver casts DO_SET_MODE params; NaN/inf read as 0 here (UB in C)."""
    return int(x) & 0xFF if isfinite(x) else 0


def _ack(cmd: VehicleCommand, result: MavResult) -> CommandAck:
    return CommandAck(cmd.command, int(result))


def handle_command(c: Commander, cmd: VehicleCommand, now_us: int) -> CommandAck | None:
    """The commander acts on `cmd` now; the ACK to send, or None where PX4 sends none."""
    handler = _HANDLERS.get(cmd.command)
    if handler is None:
        return _ack(cmd, MavResult.UNSUPPORTED)  # Commander.cpp default: -> UNSUPPORTED
    return handler(c, cmd, now_us)


# ---- ARM_DISARM (400) ------------------------------------------------------------------------------------------
def _arm_disarm(c: Commander, cmd: VehicleCommand, now_us: int) -> CommandAck | None:
    p1 = cmd.param(1)
    # SAFER THAN PX4: lroundf(NaN/inf) is undefined in C (x86 gives LONG_MIN, others may give 0 = disarm); we treat
    # a non-finite param1 like any other invalid value: the text and no ACK.
    action = lround(p1) if isfinite(p1) else None
    if action not in (0, 1):
        c.say(Severity.CRITICAL, f"Unsupported ARM_DISARM param: {p1:.3f}", is_event=False)
        return None  # cmd_result stays UNSUPPORTED, which this path never answers
    p2 = cmd.param(2)
    forced = isfinite(p2) and lround(p2) == FORCE_MAGIC
    if action == 1:
        # arm(reason, run_preflight_checks = from_external || !forced): -f only bypasses checks from the shell
        ok = c.arm(now_us, external=cmd.from_external, run_checks=cmd.from_external or not forced)
    else:
        ok = c.disarm("external command" if cmd.from_external else "internal command", forced=forced)
    return _ack(cmd, MavResult.ACCEPTED if ok else MavResult.TEMPORARILY_REJECTED)


# ---- DO_SET_MODE (176) -----------------------------------------------------------------------------------------
def _desired_mode(c: Commander, cmd: VehicleCommand) -> NavState | None:
    base_mode, main, sub = _uint8(cmd.param(1)), _uint8(cmd.param(2)), _uint8(cmd.param(3))
    if base_mode & MODE_FLAG_CUSTOM_MODE_ENABLED:
        nav = nav_state_from_main_sub(main, sub)
        if nav is None:
            if main == MainMode.AUTO:
                c.say(Severity.CRITICAL, "Unsupported auto mode", is_event=False)
            else:
                c.say(Severity.CRITICAL, "Unsupported main mode")
        return nav
    if base_mode & MODE_FLAG_AUTO_ENABLED:
        return NavState.AUTO_MISSION
    if base_mode & MODE_FLAG_MANUAL_INPUT_ENABLED:
        if base_mode & MODE_FLAG_GUIDED_ENABLED:
            return NavState.POSCTL
        if base_mode & MODE_FLAG_STABILIZE_ENABLED:
            return NavState.STAB
        return NavState.MANUAL
    c.say(Severity.CRITICAL, "Unsupported base mode", is_event=False)
    return None


def _set_mode(c: Commander, cmd: VehicleCommand, now_us: int) -> CommandAck:
    desired = _desired_mode(c, cmd)
    if desired is None:
        return _ack(cmd, MavResult.TEMPORARILY_REJECTED)
    if c.change_mode(desired):
        return _ack(cmd, MavResult.ACCEPTED)
    if cmd.source_component == MISSION_PLANNER_COMPID:
        c.reject_mode_text(desired, now_us, rate_limited=True)
    return _ack(cmd, MavResult.TEMPORARILY_REJECTED)


# ---- mode commands: TAKEOFF (22), LAND (21), RTL (20), REPOSITION (192) ----------------------------------------
def _switch(c: Commander, cmd: VehicleCommand, now_us: int, nav: NavState, ok_text: str | None) -> CommandAck:
    if c.change_mode(nav):
        if ok_text:
            c.say(Severity.INFO, ok_text)
        return _ack(cmd, MavResult.ACCEPTED)
    c.reject_mode_text(nav, now_us)
    return _ack(cmd, MavResult.TEMPORARILY_REJECTED)


def _takeoff(c: Commander, cmd: VehicleCommand, now_us: int) -> CommandAck:
    ack = _switch(c, cmd, now_us, NavState.AUTO_TAKEOFF, None)
    if ack.result == MavResult.ACCEPTED:
        # navigator: param7 = target altitude AMSL (NaN -> MIS_TAKEOFF_ALT above here), param5/6 lat/lon; yaw ignored
        c.nav_commands.append(NavCommand(NavCommandKind.TAKEOFF, cmd.param(5), cmd.param(6), cmd.param(7)))
    return ack


def _land(c: Commander, cmd: VehicleCommand, now_us: int) -> CommandAck:
    # v1.15-v1.17: not forced; armed and Land cannot run -> TEMPORARILY_REJECTED (main forces it)
    return _switch(c, cmd, now_us, NavState.AUTO_LAND, "Landing at current position")


def _rtl(c: Commander, cmd: VehicleCommand, now_us: int) -> CommandAck:
    return _switch(c, cmd, now_us, NavState.AUTO_RTL, "Returning to launch")


def _reposition(c: Commander, cmd: VehicleCommand, now_us: int) -> CommandAck:
    p2 = cmd.param(2)
    flags = int(p2) if isfinite(p2) else 0
    if flags != REPOSITION_FLAG_CHANGE_MODE:
        return _ack(cmd, MavResult.UNSUPPORTED)  # v1.15-v1.17: only "change mode" is supported
    ack = _switch(c, cmd, now_us, NavState.AUTO_LOITER, None)
    if ack.result == MavResult.ACCEPTED and c.armed:
        # navigator_main.cpp: lat p5, lon p6, alt p7 AMSL (NaN -> current), yaw p4 rad, ground speed p1
        c.nav_commands.append(NavCommand(NavCommandKind.REPOSITION, cmd.param(5), cmd.param(6), cmd.param(7),
                                         cmd.param(4), cmd.param(1)))
    return ack


def _change_altitude(c: Commander, cmd: VehicleCommand, now_us: int) -> CommandAck:
    if c.nav_state not in (NavState.AUTO_LOITER, NavState.GUIDED_COURSE) or not isfinite(cmd.param(1)):
        return _ack(cmd, MavResult.DENIED)
    alt = cmd.param(1)
    if _uint8(cmd.param(2)) == MavFrame.GLOBAL_RELATIVE_ALT and c.home is not None:  # above home
        alt += c.home.alt_amsl_m
    if c.armed:
        c.nav_commands.append(NavCommand(NavCommandKind.CHANGE_ALTITUDE, alt_amsl_m=alt))
    return _ack(cmd, MavResult.ACCEPTED)


def _orbit(c: Commander, cmd: VehicleCommand, now_us: int) -> CommandAck:
    """Commander.cpp VEHICLE_CMD_DO_ORBIT (multicopter): the user's mode becomes Orbit, nothing more; the orbit flight
    task applies the parameters (and says "Orbit radius limit exceeded" itself, after this ACCEPTED)."""
    if not c.change_mode(NavState.ORBIT):
        c.say(Severity.CRITICAL, "Orbit command rejected", is_event=False)
        return _ack(cmd, MavResult.TEMPORARILY_REJECTED)
    # param1 radius (sign: direction), param2 velocity, param3 yaw behaviour, param5/6 centre, param7 altitude AMSL
    c.nav_commands.append(NavCommand(NavCommandKind.ORBIT, cmd.param(5), cmd.param(6), cmd.param(7),
                                     speed_m_s=cmd.param(2), radius_m=cmd.param(1), yaw_behaviour=cmd.param(3)))
    return _ack(cmd, MavResult.ACCEPTED)


# ---- the rest --------------------------------------------------------------------------------------------------
def _set_home(c: Commander, cmd: VehicleCommand, now_us: int) -> CommandAck:
    if cmd.param(1) > 0.5:
        ok = c.home_here()
    else:
        lat, lon, alt = cmd.param(5), cmd.param(6), cmd.param(7)
        if not (isfinite(lat) and isfinite(lon) and isfinite(alt)):
            return _ack(cmd, MavResult.DENIED)
        yaw_deg = cmd.param(4)
        yaw = math.radians(yaw_deg) % (2 * math.pi) if isfinite(yaw_deg) else math.nan
        ok = c.home_from_global(lat, lon, alt, yaw)
    return _ack(cmd, MavResult.ACCEPTED if ok else MavResult.TEMPORARILY_REJECTED)


def _mission_start(c: Commander, cmd: VehicleCommand, now_us: int) -> CommandAck:
    """Commander.cpp MISSION_START: a valid mission and a first item in -1..count-1 -> AUTO.MISSION and arm; the
    navigator then starts at param1 (navigator_main.cpp: when >= 0)."""
    store = c.mission_store
    if store is None or not c.mission_valid:
        c.say(Severity.CRITICAL, "Mission start denied! No valid mission")
        return _ack(cmd, MavResult.DENIED)
    first = cmd.param(1)
    if not (isfinite(first) and -1 <= first < store.count(0)):
        return _ack(cmd, MavResult.DENIED)
    if not (c.change_mode(NavState.AUTO_MISSION) and c.arm(now_us, external=cmd.from_external, run_checks=True,
                                                           reason="mission start")):
        c.reject_mode_text(NavState.AUTO_MISSION, now_us)
        return _ack(cmd, MavResult.TEMPORARILY_REJECTED)
    if first >= 0:
        store.set_current(int(first))
    return _ack(cmd, MavResult.ACCEPTED)


def _set_mission_current(c: Commander, cmd: VehicleCommand, now_us: int) -> CommandAck:
    """navigator_main.cpp DO_SET_MISSION_CURRENT: param1 the item (-1: keep), param2 a MAV_BOOL: 1 resets the DO_JUMP
    counters and the completion (Mission::set_current_mission_index); FAILED out of range or without a mission."""
    p1, p2 = cmd.param(1), cmd.param(2)
    if not (isfinite(p1) and p1 >= -1 and isfinite(p2) and p2 in (0.0, 1.0)):
        return _ack(cmd, MavResult.DENIED)
    store = c.mission_store
    if store is None or not c.mission_valid or not (int(p1) == -1 or store.set_current(int(p1))):
        return _ack(cmd, MavResult.FAILED)
    if p2 == 1.0:
        store.reset_jumps()
    return _ack(cmd, MavResult.ACCEPTED)


def _termination(c: Commander, cmd: VehicleCommand, now_us: int) -> CommandAck:
    if cmd.param(1) > 0.5:
        c.terminated = True
        c.say(Severity.WARNING, "forcing failsafe (termination)", is_event=False, statustext=False)
    else:
        c.terminated = False
        c.say(Severity.WARNING, "disabling failsafe and termination", is_event=False, statustext=False)
    return _ack(cmd, MavResult.ACCEPTED)


def _calibration(c: Commander, cmd: VehicleCommand, now_us: int) -> CommandAck:
    c.say(Severity.CRITICAL, "Calibration denied: not supported in SIH mode")
    return _ack(cmd, MavResult.DENIED)


def _reboot(c: Commander, cmd: VehicleCommand, now_us: int) -> CommandAck:
    """Commander.cpp: `const int param1 = cmd.param1`; 0 nothing, 1 reboot, 2 shutdown, only while disarmed."""
    p1 = cmd.param(1)
    action = int(p1) if isfinite(p1) else -1
    if action == 0:
        return _ack(cmd, MavResult.ACCEPTED)
    if action not in (1, 2) or c.armed:
        return _ack(cmd, MavResult.DENIED)
    if action == 1:
        c.reboot_requested = True  # the Vehicle resets at its next step, after this ACK went out
    return _ack(cmd, MavResult.ACCEPTED)  # shutdown: acknowledged; stopping the process is the runner's business


def _prearm_checks(c: Commander, cmd: VehicleCommand, now_us: int) -> CommandAck:
    """RUN_PREARM_CHECKS: the health and arming check report goes out now (HealthAndArmingChecks::update(true))."""
    c.report_health(now_us, force=True)
    return _ack(cmd, MavResult.ACCEPTED)


_Handler = Callable[[Commander, VehicleCommand, int], "CommandAck | None"]
_HANDLERS: dict[int, _Handler] = {
    MavCmd.COMPONENT_ARM_DISARM: _arm_disarm,
    MavCmd.DO_SET_MODE: _set_mode,
    MavCmd.NAV_TAKEOFF: _takeoff,
    MavCmd.NAV_LAND: _land,
    MavCmd.NAV_RETURN_TO_LAUNCH: _rtl,
    MavCmd.DO_REPOSITION: _reposition,
    MavCmd.DO_ORBIT: _orbit,
    MavCmd.DO_SET_HOME: _set_home,
    MavCmd.MISSION_START: _mission_start,
    MavCmd.DO_SET_MISSION_CURRENT: _set_mission_current,
    MavCmd.DO_FLIGHTTERMINATION: _termination,
    MavCmd.DO_CHANGE_ALTITUDE: _change_altitude,
    MavCmd.PREFLIGHT_CALIBRATION: _calibration,
    MavCmd.PREFLIGHT_REBOOT_SHUTDOWN: _reboot,
    MavCmd.RUN_PREARM_CHECKS: _prearm_checks,
}
