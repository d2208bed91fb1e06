"""ExitPlan (--on-exit) on its own: a vehicle armed on the ground is disarmed, not landed (issue 25.6); a disarm
that PX4 refuses because the vehicle lifted off meanwhile falls back to the --on-exit action."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

from joyfly.link.vehicle_link import CommandHandle, VehicleState
from joyfly.session.retry import ExitPlan, Outcome

ARM_DISARM, NAV_LAND = 400, 21
ACCEPTED, DENIED = 0, 2


@dataclass
class StubLink:
    """What ExitPlan reads and sends: the vehicle's state, commands answered by `answer` (command -> MAV_RESULT)."""

    state: VehicleState
    answer: dict[int, int]
    sent: list[CommandHandle] = field(default_factory=list)
    statustexts: list[object] = field(default_factory=list)

    def _command(self, command: int, *params: float) -> CommandHandle:
        handle = CommandHandle(command, params, 0.0)
        handle.result = self.answer.get(command)
        self.sent.append(handle)
        return handle

    def arm(self, arm: bool = True) -> CommandHandle:
        return self._command(ARM_DISARM, float(arm))

    def land(self) -> CommandHandle:
        return self._command(NAV_LAND)


def armed(landed_state: int) -> VehicleState:
    return VehicleState(sysid=1, last_heartbeat_s=0.0, armed=True, landed_state=landed_state)


def run(plan: ExitPlan, link: StubLink, until_s: float) -> None:
    t = 0.0
    while t < until_s:
        plan.update(t)
        t += 0.05


def test_on_the_ground_the_exit_disarms_and_never_lands() -> None:
    link = StubLink(armed(landed_state=1), {ARM_DISARM: ACCEPTED})
    plan = ExitPlan("land", link, 0.0)  # type: ignore[arg-type]
    assert plan.disarming
    run(plan, link, 0.5)
    assert [(h.command, h.params) for h in link.sent] == [(ARM_DISARM, (0.0,))]
    link.state = replace(link.state, armed=False, last_heartbeat_s=0.6)
    assert plan.update(0.7) is Outcome.DONE and plan.commanded_mode is None


def test_in_the_air_the_exit_lands() -> None:
    link = StubLink(armed(landed_state=2), {NAV_LAND: ACCEPTED})
    plan = ExitPlan("land", link, 0.0)  # type: ignore[arg-type]
    run(plan, link, 0.5)
    assert not plan.disarming and [h.command for h in link.sent] == [NAV_LAND]


def test_a_disarm_refused_because_it_lifted_off_lands_instead() -> None:
    link = StubLink(armed(landed_state=1), {ARM_DISARM: DENIED, NAV_LAND: ACCEPTED})  # "Disarming denied: not landed"
    plan = ExitPlan("land", link, 0.0)  # type: ignore[arg-type]
    run(plan, link, 2.0)
    assert [h.command for h in link.sent] == [ARM_DISARM, NAV_LAND] and not plan.disarming
    assert plan.commanded_mode == "AUTO.LAND"
