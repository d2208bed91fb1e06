"""The commander state machines alone, in simulated time: DO_SET_MODE table (reference 3.3), mode commands,
offboard-loss failsafe (4.3), auto-disarm (5.6), takeoff completion, landed texts."""

from __future__ import annotations

import math

import pytest

from sitl_emu.commander.commander import Commander
from sitl_emu.commander.commands import handle_command
from sitl_emu.navigator.commands import NavCommandKind
from sitl_emu.params import default_registry
from sitl_emu.px4 import MavResult, MavState, NavState, custom_mode, decode_custom_mode
from sitl_emu.types import HomePosition, OffboardControlMode, VehicleCommand

NAN = math.nan
S = 1_000_000
HERE = HomePosition(47.397742, 8.545594, 488.0, (0.0, 0.0, 0.0), 0.0)
POS = OffboardControlMode(position=True)


class Harness:
    def __init__(self, *, ready: bool = True, t0_us: int = 5 * S) -> None:
        self.texts: list[str] = []
        self.params = default_registry()
        self.c = Commander(self.params, lambda sev, mod, text, ev, st: self.texts.append(text),
                           here=lambda: HERE if self.ready else None)
        self.ready = ready
        self.finished = False
        self.tick(t0_us)

    def tick(self, now_us: int) -> None:
        self.c.observe(now_us, estimator_ready=self.ready, task_finished=self.finished)
        self.c.update(now_us)

    def run(self, seconds: float, dt_us: int = 4000, stream: OffboardControlMode | None = None) -> None:
        end = self.c.now_us + int(seconds * S)
        while self.c.now_us < end:
            if stream is not None:
                self.c.offboard_signal(self.c.now_us, stream)
            self.tick(self.c.now_us + dt_us)

    def cmd(self, command: int, *params: float, compid: int = 190, external: bool = True):
        p = tuple(params) + (NAN,) * (7 - len(params))
        return handle_command(self.c, VehicleCommand(command, p, source_component=compid, from_external=external),
                              self.c.now_us)

    def set_mode(self, nav: NavState, compid: int = 190):
        main, sub = decode_custom_mode(custom_mode(nav))
        return self.cmd(176, 1.0, main, sub, compid=compid)

    def arm_and_fly(self) -> None:
        assert self.cmd(400, 1.0).result == MavResult.ACCEPTED
        self.c.on_land_detector(False, False)


# ---- DO_SET_MODE (3.3) -----------------------------------------------------------------------------------------
@pytest.mark.parametrize("nav", [NavState.OFFBOARD, NavState.AUTO_RTL, NavState.AUTO_LAND, NavState.POSCTL,
                                 NavState.MANUAL, NavState.AUTO_MISSION, NavState.AUTO_TAKEOFF, NavState.STAB])
def test_any_mode_is_accepted_while_disarmed(nav: NavState) -> None:
    h = Harness()
    assert h.set_mode(nav).result == MavResult.ACCEPTED
    assert h.c.nav_state == nav and h.c.intention.user_intended == nav


@pytest.mark.parametrize(("nav", "result"), [
    (NavState.AUTO_LOITER, MavResult.ACCEPTED),
    (NavState.AUTO_RTL, MavResult.ACCEPTED),
    (NavState.AUTO_LAND, MavResult.ACCEPTED),
    (NavState.OFFBOARD, MavResult.TEMPORARILY_REJECTED),  # no setpoint stream
    (NavState.POSCTL, MavResult.TEMPORARILY_REJECTED),  # no joystick
    (NavState.ALTCTL, MavResult.TEMPORARILY_REJECTED),
    (NavState.AUTO_MISSION, MavResult.TEMPORARILY_REJECTED),  # no mission
])
def test_mode_change_when_armed_needs_can_run(nav: NavState, result: MavResult) -> None:
    h = Harness()
    h.arm_and_fly()
    assert h.set_mode(nav).result == result
    if result == MavResult.ACCEPTED:
        assert h.c.nav_state == nav
    else:
        assert h.c.nav_state == NavState.AUTO_LOITER


def test_offboard_accepted_when_armed_with_fresh_stream() -> None:
    h = Harness()
    h.arm_and_fly()
    h.run(0.5, stream=POS)
    assert h.set_mode(NavState.OFFBOARD).result == MavResult.ACCEPTED
    assert h.c.nav_state == NavState.OFFBOARD


def test_reject_text_only_for_mission_planner_and_once_per_second() -> None:
    h = Harness()
    h.arm_and_fly()
    h.texts.clear()
    assert h.set_mode(NavState.POSCTL, compid=1).result == MavResult.TEMPORARILY_REJECTED
    assert h.texts == []
    h.set_mode(NavState.POSCTL)
    h.set_mode(NavState.POSCTL)
    assert h.texts == ["Switching to Position is currently not available"]
    h.run(1.0)
    h.set_mode(NavState.OFFBOARD)
    assert h.texts[-1] == "Switching to Offboard is currently not available"


@pytest.mark.parametrize(("base", "main", "sub", "nav", "text"), [
    (4, 0, 0, NavState.AUTO_MISSION, None),
    (64 | 8, 0, 0, NavState.POSCTL, None),
    (64 | 16, 0, 0, NavState.STAB, None),
    (64, 0, 0, NavState.MANUAL, None),
    (0, 0, 0, None, "Unsupported base mode"),
    (1, 12, 0, None, "Unsupported main mode"),
    (1, 4, 7, None, "Unsupported auto mode"),
    (1, 4, 0, NavState.AUTO_MISSION, None),
    (1, 3, 2, NavState.POSITION_SLOW, None),
    (1 | 128, 6, 0, NavState.OFFBOARD, None),
])
def test_set_mode_decoding(base: int, main: int, sub: int, nav: NavState | None, text: str | None) -> None:
    h = Harness()
    ack = h.cmd(176, base, main, sub)
    if nav is None:
        assert ack.result == MavResult.TEMPORARILY_REJECTED and h.c.nav_state == NavState.AUTO_LOITER
        assert text in h.texts
    else:
        assert ack.result == MavResult.ACCEPTED and h.c.nav_state == nav


# ---- mode commands (3.5-3.8, 3.13) -----------------------------------------------------------------------------
def test_takeoff_accepted_while_disarmed_and_queues_altitude() -> None:
    h = Harness()
    assert h.cmd(22, NAN, NAN, NAN, NAN, NAN, NAN, 500.0).result == MavResult.ACCEPTED
    assert h.c.nav_state == NavState.AUTO_TAKEOFF
    assert h.c.nav_commands[-1].kind is NavCommandKind.TAKEOFF and h.c.nav_commands[-1].alt_amsl_m == 500.0


def test_land_and_return_texts() -> None:
    h = Harness()
    h.arm_and_fly()
    assert h.cmd(20).result == MavResult.ACCEPTED and h.c.nav_state == NavState.AUTO_RTL
    assert "Returning to launch" in h.texts
    assert h.cmd(21).result == MavResult.ACCEPTED and h.c.nav_state == NavState.AUTO_LAND
    assert "Landing at current position" in h.texts


def test_return_rejected_without_home() -> None:
    h = Harness()
    h.params.set("COM_HOME_EN", 0)
    h.c.home = None
    h.c.arm(h.c.now_us, external=True, run_checks=True)
    h.c.on_land_detector(False, False)
    assert h.c.home is None
    assert h.cmd(20).result == MavResult.TEMPORARILY_REJECTED
    assert "Switching to Return is currently not available" in h.texts


@pytest.mark.parametrize(("flags", "result"), [(1, MavResult.ACCEPTED), (0, MavResult.UNSUPPORTED),
                                               (3, MavResult.UNSUPPORTED), (NAN, MavResult.UNSUPPORTED)])
def test_reposition_flags(flags: float, result: MavResult) -> None:
    h = Harness()
    h.arm_and_fly()
    ack = h.cmd(192, -1.0, flags, NAN, NAN, 47.3978, 8.5456, 495.0)
    assert ack.result == result
    assert bool(h.c.nav_commands) == (result == MavResult.ACCEPTED)


@pytest.mark.parametrize(("command", "result", "text"), [
    (300, MavResult.DENIED, "Mission start denied! No valid mission"),
    (241, MavResult.DENIED, "Calibration denied: not supported in SIH mode"),
    (401, MavResult.ACCEPTED, None),
    (178, MavResult.UNSUPPORTED, None),
    (31000, MavResult.UNSUPPORTED, None),
])
def test_other_commands(command: int, result: MavResult, text: str | None) -> None:
    h = Harness()
    assert h.cmd(command, 0.0).result == result
    if text:
        assert text in h.texts


def test_reboot_requested_only_when_disarmed() -> None:
    h = Harness()
    assert h.cmd(246, 0.0).result == MavResult.ACCEPTED and not h.c.reboot_requested
    assert h.cmd(246, 3.0).result == MavResult.DENIED and not h.c.reboot_requested
    assert h.cmd(246, NAN).result == MavResult.DENIED and not h.c.reboot_requested
    assert h.cmd(246, 1.0).result == MavResult.ACCEPTED and h.c.reboot_requested
    h = Harness()
    h.arm_and_fly()
    assert h.cmd(246, 1.0).result == MavResult.DENIED and not h.c.reboot_requested


def test_set_home_current_and_explicit() -> None:
    h = Harness()
    h.c._ned_of = lambda lat, lon, alt: (1.0, 2.0, 488.0 - alt)
    assert h.cmd(179, 0.0, NAN, NAN, 90.0, 47.3978, 8.5456, 490.0).result == MavResult.ACCEPTED
    assert h.c.home.pos_ned_m == (1.0, 2.0, -2.0) and h.c.home.yaw_rad == pytest.approx(math.pi / 2)
    assert h.cmd(179, 0.0, NAN, NAN, NAN, NAN, 8.5, 490.0).result == MavResult.DENIED
    assert h.cmd(179, 1.0).result == MavResult.ACCEPTED and h.c.home == HERE


# ---- offboard loss failsafe (4.3) ------------------------------------------------------------------------------
def _in_offboard() -> Harness:
    h = Harness()
    h.run(0.2, stream=POS)
    h.arm_and_fly()
    assert h.set_mode(NavState.OFFBOARD).result == MavResult.ACCEPTED
    h.run(2.0, stream=POS)
    assert h.c.nav_state == NavState.OFFBOARD and not h.c.failsafe
    h.texts.clear()
    return h


def test_offboard_loss_returns_and_resumes() -> None:
    h = _in_offboard()
    h.run(0.9)
    assert h.c.nav_state == NavState.OFFBOARD
    h.run(0.2)
    assert h.c.nav_state == NavState.AUTO_RTL and h.c.failsafe
    assert h.c.intention.user_intended == NavState.OFFBOARD
    assert h.texts.count("Failsafe activated") == 1
    assert h.c.system_status() == MavState.CRITICAL
    h.run(0.1, stream=POS)
    assert h.c.nav_state == NavState.OFFBOARD and not h.c.failsafe
    assert h.c.system_status() == MavState.ACTIVE


@pytest.mark.parametrize(("action", "nav"), [(0, NavState.AUTO_RTL), (1, NavState.AUTO_RTL), (2, NavState.AUTO_RTL),
                                             (3, NavState.AUTO_RTL), (4, NavState.AUTO_LAND),
                                             (5, NavState.AUTO_LOITER), (6, NavState.TERMINATION)])
def test_offboard_loss_action_param(action: int, nav: NavState) -> None:
    h = _in_offboard()
    h.params.set("COM_OBL_RC_ACT", action)
    h.run(1.2)
    assert h.c.nav_state == nav and h.c.armed


def test_offboard_loss_manual_fallback_follows_nav_rcl_act() -> None:
    h = _in_offboard()
    h.params.set("NAV_RCL_ACT", 3)
    h.run(1.2)
    assert h.c.nav_state == NavState.AUTO_LAND


def test_offboard_loss_disarm_action() -> None:
    h = _in_offboard()
    h.params.set("COM_OBL_RC_ACT", 7)
    h.run(1.2)
    assert not h.c.armed and "Disarmed by failsafe" in h.texts


def test_explicit_mode_change_ends_failsafe() -> None:
    h = _in_offboard()
    h.run(1.2)
    assert h.c.failsafe
    assert h.set_mode(NavState.AUTO_LOITER).result == MavResult.ACCEPTED
    assert h.c.nav_state == NavState.AUTO_LOITER and not h.c.failsafe
    h.run(0.5, stream=POS)
    assert h.c.nav_state == NavState.AUTO_LOITER  # the user left OFFBOARD: no automatic return


def test_failsafe_disarm_returns_to_offboard_intention() -> None:
    h = _in_offboard()
    h.run(1.2)
    h.c.on_land_detector(True, True)
    h.run(2.1)
    assert not h.c.armed and "Disarmed by landing" in h.texts
    assert h.c.nav_state == NavState.OFFBOARD  # UserModeIntention::onDisarm


# ---- auto-disarm (5.6), takeoff completion, landed texts --------------------------------------------------------
def test_preflight_auto_disarm_after_spoolup_plus_prflt() -> None:
    h = Harness()
    h.cmd(400, 1.0)
    h.run(10.9)
    assert h.c.armed
    h.run(0.11)
    assert not h.c.armed and "Disarmed by auto preflight disarming" in h.texts


def test_landing_disarm_two_seconds_after_landing() -> None:
    h = Harness()
    h.arm_and_fly()
    assert "Takeoff detected" in h.texts and h.c.have_taken_off
    h.run(20.0)
    assert h.c.armed  # airborne: no preflight disarm
    h.c.on_land_detector(True, True)
    assert "Landing detected" in h.texts
    h.run(1.9)
    assert h.c.armed
    h.run(0.15)
    assert not h.c.armed and h.texts[-1] == "Disarmed by landing"


def test_landing_disarm_disabled() -> None:
    h = Harness()
    h.params.set("COM_DISARM_LAND", -1.0)
    h.arm_and_fly()
    h.c.on_land_detector(True, True)
    h.run(5.0)
    assert h.c.armed


def test_takeoff_finished_switches_to_hold() -> None:
    h = Harness()
    h.cmd(22)
    h.arm_and_fly()
    h.run(0.1)
    assert h.c.nav_state == NavState.AUTO_TAKEOFF
    h.finished = True
    h.run(0.01)
    assert h.c.nav_state == NavState.AUTO_LOITER and h.c.intention.user_intended == NavState.AUTO_LOITER


def test_ready_status_and_text() -> None:
    h = Harness(ready=False, t0_us=0)
    assert h.c.system_status() == MavState.UNINIT and not h.c.pre_flight_checks_pass()
    h.ready = True
    h.run(0.01)
    assert h.c.system_status() == MavState.STANDBY and h.texts == ["Ready for takeoff!"]
    assert h.c.home == HERE
    h.set_mode(NavState.AUTO_RTL)
    assert h.c.system_status() == MavState.UNINIT  # RTL prevents arming


def test_termination_holds_until_disarm() -> None:
    h = Harness()
    h.arm_and_fly()
    assert h.cmd(185, 1.0).result == MavResult.ACCEPTED
    h.run(0.01)
    assert h.c.nav_state == NavState.TERMINATION and h.c.system_status() == MavState.FLIGHT_TERMINATION
    assert h.set_mode(NavState.AUTO_LOITER).result == MavResult.TEMPORARILY_REJECTED


def test_pre_flight_checks_pass_while_flying_in_return() -> None:
    h = Harness()
    h.arm_and_fly()
    h.cmd(20)
    assert h.c.nav_state == NavState.AUTO_RTL and h.c.pre_flight_checks_pass()
