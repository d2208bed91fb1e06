"""ARM_DISARM (400) refusal table, one row per case of reference section 3.2, on the commander alone."""

from __future__ import annotations

import math
from dataclasses import dataclass

import pytest

from sitl_emu.commander.commander import Commander
from sitl_emu.commander.commands import handle_command
from sitl_emu.params import default_registry
from sitl_emu.px4 import MavResult, NavState
from sitl_emu.types import HomePosition, OffboardControlMode, VehicleCommand

NAN = math.nan
T0 = 5_000_000
HERE = HomePosition(47.397742, 8.545594, 488.0, (0.0, 0.0, 0.0), 0.0)


class Harness:
    def __init__(self, *, ready: bool = True) -> None:
        self.texts: list[str] = []
        self.ready = ready
        self.here = HERE
        self.c = Commander(default_registry(), lambda sev, mod, text, ev, st: self.texts.append(text),
                           here=lambda: self.here if self.ready else None)
        self.tick(T0)

    def tick(self, now_us: int) -> None:
        self.c.observe(now_us, estimator_ready=self.ready)
        self.c.update(now_us)

    def cmd(self, command: int, *params: float, external: bool = True, compid: int = 190):
        p = tuple(params) + (NAN,) * (7 - len(params))
        return handle_command(self.c, VehicleCommand(command, p, source_component=compid, from_external=external),
                              self.c.now_us)


@dataclass(frozen=True)
class Case:
    name: str
    mode: NavState = NavState.AUTO_LOITER
    ready: bool = True
    offboard_age_s: float | None = None  # seconds since the last offboard signal, None = never
    param1: float = 1.0
    param2: float = 0.0
    external: bool = True
    armed_before: bool = False
    in_air: bool = False
    maybe_landed: bool = False
    result: int | None = MavResult.ACCEPTED
    text: str | None = None
    armed_after: bool = True


ARM_DENIED = "Arming denied: Resolve system health failures first"
CASES = [
    Case("hold ready", text="Armed by external command"),
    Case("takeoff mode ready", mode=NavState.AUTO_TAKEOFF, text="Armed by external command"),
    Case("not ready", ready=False, result=MavResult.TEMPORARILY_REJECTED, text=ARM_DENIED, armed_after=False),
    Case("return mode", mode=NavState.AUTO_RTL, result=MavResult.TEMPORARILY_REJECTED, text=ARM_DENIED,
         armed_after=False),
    Case("land mode", mode=NavState.AUTO_LAND, result=MavResult.TEMPORARILY_REJECTED, text=ARM_DENIED,
         armed_after=False),
    Case("mission without a mission", mode=NavState.AUTO_MISSION, result=MavResult.TEMPORARILY_REJECTED,
         text=ARM_DENIED, armed_after=False),
    Case("offboard never streamed", mode=NavState.OFFBOARD, result=MavResult.TEMPORARILY_REJECTED, text=ARM_DENIED,
         armed_after=False),
    Case("offboard stale stream", mode=NavState.OFFBOARD, offboard_age_s=1.0, result=MavResult.TEMPORARILY_REJECTED,
         text=ARM_DENIED, armed_after=False),
    Case("offboard fresh stream", mode=NavState.OFFBOARD, offboard_age_s=0.9, text="Armed by external command"),
    Case("position mode, no joystick", mode=NavState.POSCTL, result=MavResult.TEMPORARILY_REJECTED, text=ARM_DENIED,
         armed_after=False),
    Case("manual mode, no joystick", mode=NavState.MANUAL, result=MavResult.TEMPORARILY_REJECTED, text=ARM_DENIED,
         armed_after=False),
    Case("stabilized mode, no joystick", mode=NavState.STAB, result=MavResult.TEMPORARILY_REJECTED,
         text=ARM_DENIED, armed_after=False),
    Case("altitude mode, no joystick", mode=NavState.ALTCTL, result=MavResult.TEMPORARILY_REJECTED,
         text=ARM_DENIED, armed_after=False),
    Case("acro mode, no joystick", mode=NavState.ACRO, result=MavResult.TEMPORARILY_REJECTED, text=ARM_DENIED,
         armed_after=False),
    Case("external 21196 does not bypass checks", mode=NavState.AUTO_RTL, param2=21196,
         result=MavResult.TEMPORARILY_REJECTED, text=ARM_DENIED, armed_after=False),
    Case("shell -f bypasses checks", mode=NavState.AUTO_RTL, param2=21196, external=False,
         text="Armed by internal command"),
    Case("shell without -f runs checks", mode=NavState.AUTO_RTL, external=False,
         result=MavResult.TEMPORARILY_REJECTED, text=ARM_DENIED, armed_after=False),
    Case("already armed", armed_before=True, text=None),
    Case("param1 rounds: 0.6 arms", param1=0.6, text="Armed by external command"),
    Case("param1 2: no ACK", param1=2.0, result=None, text="Unsupported ARM_DISARM param: 2.000", armed_after=False),
    Case("param1 -1: no ACK", param1=-1.0, result=None, text="Unsupported ARM_DISARM param: -1.000",
         armed_after=False),
    Case("param1 NaN: no ACK (safer than PX4)", param1=NAN, result=None, text="Unsupported ARM_DISARM param: nan",
         armed_after=False),
    Case("param1 inf: no ACK (safer than PX4)", param1=math.inf, result=None,
         text="Unsupported ARM_DISARM param: inf", armed_after=False),
    # disarm
    Case("disarm when disarmed", param1=0.0, armed_after=False),
    Case("disarm landed", param1=0.0, armed_before=True, text="Disarmed by external command", armed_after=False),
    Case("disarm rounds: 0.4 disarms", param1=0.4, armed_before=True, text="Disarmed by external command",
         armed_after=False),
    Case("disarm in air refused", param1=0.0, armed_before=True, in_air=True,
         result=MavResult.TEMPORARILY_REJECTED, text="Disarming denied: not landed", armed_after=True),
    Case("disarm maybe landed", param1=0.0, armed_before=True, in_air=True, maybe_landed=True,
         text="Disarmed by external command", armed_after=False),
    Case("forced disarm in air", param1=0.0, param2=21196, armed_before=True, in_air=True,
         text="Disarmed by external command", armed_after=False),
    Case("shell disarm", param1=0.0, armed_before=True, external=False, text="Disarmed by internal command",
         armed_after=False),
]


def _prepare(case: Case) -> Harness:
    h = Harness(ready=case.ready)
    if case.armed_before:
        assert h.c.arm(h.c.now_us, external=True, run_checks=True)
    if case.in_air:
        h.c.on_land_detector(False, False)
        h.c.on_land_detector(False, case.maybe_landed)
    if case.offboard_age_s is not None:
        h.c.offboard_signal(h.c.now_us, OffboardControlMode(position=True))
        h.tick(h.c.now_us + int(case.offboard_age_s * 1e6))
    if h.c.nav_state != case.mode:
        assert h.c.change_mode(case.mode, force=True)
    h.texts.clear()
    return h


@pytest.mark.parametrize("case", CASES, ids=[c.name for c in CASES])
def test_arm_disarm_table(case: Case) -> None:
    h = _prepare(case)
    ack = h.cmd(400, case.param1, case.param2, external=case.external)
    if case.result is None:
        assert ack is None
    else:
        assert ack is not None and ack.command == 400 and ack.result == case.result
    if case.text is None:
        assert not any(t.startswith(("Armed", "Disarmed", "Arming", "Disarming")) for t in h.texts)
    else:
        assert case.text in h.texts
    assert h.c.armed is case.armed_after


def test_home_is_set_at_arming() -> None:
    h = Harness()
    moved = HomePosition(47.4, 8.55, 490.0, (10.0, 5.0, -2.0), 1.0)
    h.here = moved
    assert h.cmd(400, 1.0).result == MavResult.ACCEPTED
    assert h.c.home == moved


def test_disarm_reverts_to_last_sticky_mode() -> None:
    h = Harness()
    h.cmd(400, 1.0)
    h.c.on_land_detector(False, False)
    assert h.cmd(21).result == MavResult.ACCEPTED  # NAV_LAND (prevents arming: not sticky)
    assert h.c.nav_state == NavState.AUTO_LAND
    h.c.on_land_detector(True, True)
    assert h.cmd(400, 0.0).result == MavResult.ACCEPTED
    assert h.c.nav_state == NavState.AUTO_LOITER
    assert h.c.intention.user_intended == NavState.AUTO_LOITER
