"""The commander's manual-control rules, on the vehicle directly (simulated time): a pilot's takeover, the disarm
gesture in the air, COM_RCL_EXCEPT, and a vehicle armed without sticks (spec: PX4 Commander.cpp manualControlCheck,
ManualControl.cpp processStickArming, failsafe.cpp isFailsafeIgnored / _manual_control_lost_at_arming)."""

from __future__ import annotations

import math

from sitl_emu.params import default_registry
from sitl_emu.px4 import MavCmd, MavState, NavState
from sitl_emu.types import ManualControlSetpoint, VehicleCommand
from sitl_emu.vehicle.vehicle import Vehicle

NAN = math.nan
CENTRED = ManualControlSetpoint(throttle=0.0)


class Pilot:
    def __init__(self, params=None) -> None:
        self.v = Vehicle(params=params)
        self.sticks: ManualControlSetpoint | None = CENTRED

    def command(self, command: int, *params: float) -> None:
        self.v.handle_command(VehicleCommand(command, tuple(params) + (NAN,) * (7 - len(params))))

    def run(self, seconds: float) -> None:
        end = self.v.time_us + round(seconds * 1e6)
        while self.v.time_us < end:
            if self.sticks is not None and self.v.time_us % 50_000 == 0:
                self.v.manual_control_input(self.sticks)
            self.v.step()

    def texts(self) -> list[str]:
        return [e.text for e in self.v.events_after(0)]

    def flying_in_position_mode(self) -> Pilot:
        self.run(2.5)
        self.command(MavCmd.DO_SET_MODE, 1, 3, 0)
        self.command(MavCmd.COMPONENT_ARM_DISARM, 1)
        self.sticks = ManualControlSetpoint(throttle=1.0)
        self.run(6.0)
        self.sticks = CENTRED
        self.run(2.0)
        assert -self.v.snapshot().pos_ned_m[2] > 2.0
        return self


def test_moving_the_sticks_in_hold_hands_control_to_position_mode():
    p = Pilot().flying_in_position_mode()
    p.command(MavCmd.DO_SET_MODE, 1, 4, 3)  # Hold
    p.run(1.0)
    p.sticks = ManualControlSetpoint(throttle=0.0, pitch=0.8)  # one jump to a held stick: not a takeover
    p.run(1.0)
    assert p.v.commander.nav_state is NavState.AUTO_LOITER
    p.sticks = CENTRED
    p.run(1.0)
    for i in range(1, 8):  # a deliberate push over several samples
        p.sticks = ManualControlSetpoint(throttle=0.0, pitch=0.1 * i)
        p.run(0.05)
    assert p.v.commander.nav_state is NavState.POSCTL
    assert "Pilot took over using sticks" in p.texts()


def test_the_disarm_gesture_is_refused_in_the_air_without_a_word():
    p = Pilot().flying_in_position_mode()
    n = len(p.texts())
    p.sticks = ManualControlSetpoint(throttle=-1.0, yaw=-1.0)
    p.run(1.5)
    assert p.v.snapshot().armed
    assert not any("isarm" in t for t in p.texts()[n:])


def test_com_rcl_except_offboard_ignores_the_loss_in_offboard():
    params = default_registry()
    params.set("COM_RCL_EXCEPT", 4)
    p = Pilot(params).flying_in_position_mode()
    here = p.v.snapshot().pos_ned_m
    from sitl_emu.types import OffboardControlMode, TrajectorySetpoint

    def offboard() -> None:
        p.v.offboard_input(OffboardControlMode(position=True), TrajectorySetpoint(position_ned_m=here))

    offboard()
    p.command(MavCmd.DO_SET_MODE, 1, 6, 0)
    p.sticks = None
    for _ in range(40):  # 8 s of setpoints at 5 Hz and no sticks
        offboard()
        p.run(0.2)
    assert p.v.commander.nav_state is NavState.OFFBOARD
    assert "Failsafe activated" not in " ".join(p.texts())


def test_a_vehicle_armed_without_sticks_ignores_their_absence_until_they_appear():
    p = Pilot()
    p.sticks = None
    p.run(2.5)
    p.command(MavCmd.COMPONENT_ARM_DISARM, 1)
    p.command(MavCmd.NAV_TAKEOFF)
    p.run(8.0)
    assert p.v.commander.nav_state is NavState.AUTO_LOITER and not p.v.commander.failsafe
    p.sticks = CENTRED  # the sticks appear, then stop: now their loss counts
    p.run(1.0)
    p.sticks = None
    p.run(1.0)
    assert p.v.commander.failsafe and p.v.commander.nav_state is NavState.AUTO_LOITER  # the Hold before Return
    assert "Failsafe activated: entering Hold for 5 seconds" in p.texts()
    p.run(5.0)
    assert p.v.commander.nav_state is NavState.AUTO_RTL


def test_sticks_lost_in_position_mode_hold_first_then_return():
    """failsafe.cpp: a manual mode without sticks is the manual-control loss failsafe's (Hold COM_FAIL_ACT_T, then
    NAV_RCL_ACT), not an immediate mode fallback."""
    p = Pilot().flying_in_position_mode()
    n = len(p.texts())
    p.sticks = None
    p.run(1.0)
    assert p.v.commander.nav_state is NavState.AUTO_LOITER and p.v.commander.failsafe
    p.run(4.0)
    assert p.v.commander.nav_state is NavState.AUTO_LOITER
    p.run(1.0)
    assert p.v.commander.nav_state is NavState.AUTO_RTL
    assert p.texts()[n:n + 2] == ["Failsafe activated: entering Hold for 5 seconds", "Failsafe activated"]
    assert p.v.commander.intention.user_intended is NavState.POSCTL


def _one_sample_then_armed() -> Pilot:
    """MAVSDK-Python's manual_control example: one MANUAL_CONTROL, then arm (px4-recorded-facts.md section 3)."""
    p = Pilot()
    p.sticks = None
    p.run(2.5)
    p.v.manual_control_input(CENTRED)
    p.run(0.2)
    p.command(MavCmd.COMPONENT_ARM_DISARM, 1)
    return p


def test_a_takeoff_commanded_during_the_stick_loss_hold_is_a_takeover_and_flies():
    """framework.cpp getSelectedAction: a user-intended mode change while the manual-control loss holds (Hold,
    Return, Land) is a takeover; the action becomes a warning, the mode runs, and the loss acts again only after the
    sticks came back and were lost anew."""
    p = _one_sample_then_armed()
    p.run(1.0)
    assert p.v.commander.failsafe and "Failsafe activated: entering Hold for 5 seconds" in p.texts()
    assert p.v.commander.system_status() is MavState.CRITICAL
    n = len(p.texts())
    p.command(MavCmd.NAV_TAKEOFF)
    p.run(0.2)
    assert p.v.commander.nav_state is NavState.AUTO_TAKEOFF and not p.v.commander.failsafe
    assert p.v.commander.system_status() is MavState.ACTIVE
    p.run(15.0)
    assert -p.v.snapshot().pos_ned_m[2] > 2.3 and p.v.commander.nav_state is NavState.AUTO_LOITER
    assert not any(t.startswith("Failsafe") for t in p.texts()[n:])
    p.sticks = CENTRED  # the sticks come back, then go again: a new loss, a new failsafe
    p.run(1.0)
    p.sticks = None
    p.run(1.0)
    assert p.v.commander.failsafe and p.texts()[-1] == "Failsafe activated: entering Hold for 5 seconds"


def test_the_stick_loss_after_a_takeoff_holds_then_returns():
    """px4-recorded-facts.md section 3: taken off before the loss is noticed, the vehicle holds, then returns."""
    p = _one_sample_then_armed()
    p.command(MavCmd.NAV_TAKEOFF)
    p.run(1.0)
    assert p.v.commander.nav_state is NavState.AUTO_LOITER and p.v.commander.failsafe
    p.run(5.0)
    assert p.v.commander.nav_state is NavState.AUTO_RTL
    assert p.texts()[-3:-1] == ["Failsafe activated: entering Hold for 5 seconds", "Failsafe activated"]
    p.run(15.0)
    # disarmed into Hold, not back into the take-off (PX4 PR 25735: a take-off is never the mode after disarming)
    assert not p.v.commander.armed and p.v.commander.nav_state is NavState.AUTO_LOITER
