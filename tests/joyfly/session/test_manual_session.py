"""`--control position` / `altitude` (ManualSession) in simulated time against a fake PX4 that takes MANUAL_CONTROL
(tests/support/joyfly_manual_fake.py), over an in-memory MAVLink link: which messages go out in which order, what
the sticks become, and how the flight ends."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import pytest
from support.joyfly_fakes import LAND, LOITER, RTL, TimedSticks
from support.joyfly_manual_fake import ALTCTL, POSCTL, ManualFakeVehicle
from support.joyfly_sim import SimClock, memory_pair

from joyfly.dashboard import render, summary_lines
from joyfly.link.vehicle_link import VehicleLink
from joyfly.run import left_behind
from joyfly.session.core import Phase, SessionSettings
from joyfly.session.factory import make_session
from joyfly.session.manual_session import ManualSession
from joyfly.sticks.setpoints import Limits
from joyfly.types import Action, StickCommand

CENTRE = StickCommand(up=0.0)
UP = StickCommand(up=1.0)


def press(action: Action) -> StickCommand:
    return StickCommand(up=0.0, pressed=frozenset({action}))


@dataclass
class World:
    clock: SimClock
    vehicle: ManualFakeVehicle
    session: ManualSession
    trace: list[tuple[float, Phase, tuple[float, float, float]]] = field(default_factory=list)

    def run_until(self, t_s: float) -> None:
        while self.clock.now() < t_s and not self.session.finished:
            self.session.run_once()
            x, y, z = self.vehicle.pos
            self.trace.append((self.clock.now(), self.session.phase, (x, y, z)))

    def notes(self) -> str:
        return "\n".join(n.text for n in self.session.notes)

    def manual(self, after_s: float = -1.0) -> list[tuple[float, Any]]:
        return [(t, m) for t, m in self.vehicle.received("MANUAL") if t > after_s]

    def commands(self, number: int) -> list[tuple[float, Any]]:
        return self.vehicle.received(f"CMD{number}")


def make_world(steps: list[tuple[float, StickCommand]] | None = None, control: str = "position",
               **settings: Any) -> World:
    clock = SimClock(max_step_s=0.005)
    ours, theirs = memory_pair()
    vehicle = ManualFakeVehicle(theirs)
    clock.on_advance(vehicle.step)
    sticks = TimedSticks(clock, steps or [(0.0, CENTRE)])
    settings.setdefault("rate_hz", 25.0)
    session = make_session(VehicleLink(ours, clock), sticks, clock,
                           SessionSettings(limits=Limits(control=control), **settings))
    assert isinstance(session, ManualSession)
    return World(clock, vehicle, session)


def airborne(extra: list[tuple[float, StickCommand]] | None = None, **settings: Any) -> World:
    """Armed in POSCTL by ~3 s; throttle up from 4 s to 6 s (about 5 m), then centred."""
    world = make_world([(0.0, CENTRE), (4.0, UP), (6.0, CENTRE), *(extra or [])], **settings)
    world.run_until(8.0)
    assert world.session.phase is Phase.FLYING and world.vehicle.pos[2] < -3.0, world.notes()
    return world


def assert_stream_stopped_at_the_end(world: World) -> None:
    """MANUAL_CONTROL went on until the session was done (the vehicle disarmed), and stops then."""
    end, count = world.clock.now(), len(world.manual())
    world.clock.sleep(2.0)
    assert len(world.manual()) == count and world.manual()[-1][0] > end - 0.1


def test_the_sequence_is_stream_then_posctl_then_arm_with_centred_sticks() -> None:
    world = make_world()
    world.run_until(5.0)
    manual, mode, arm = world.manual(), world.commands(176), world.commands(400)
    assert mode and arm and world.vehicle.armed and world.vehicle.custom_mode == POSCTL
    assert (mode[0][1].param1, mode[0][1].param2, mode[0][1].param3) == (1, 3, 0)  # base: custom mode, POSCTL
    assert sum(1 for t, _ in manual if t < mode[0][0]) >= 10 and mode[0][0] < arm[0][0]
    assert all((m.target, m.x, m.y, m.z, m.r, m.buttons) == (1, 0, 0, 500, 0, 0) for t, m in manual if t < arm[0][0])
    assert world.session.phase is Phase.FLYING and "push the throttle up to take off" in world.notes()
    assert world.vehicle.wrong_targets == 0 and world.vehicle.pos[2] == 0.0  # centred: still on the ground


def test_altitude_control_flies_altctl() -> None:
    world = make_world(control="altitude")
    world.run_until(5.0)
    assert (world.commands(176)[0][1].param2, world.vehicle.custom_mode) == (2, ALTCTL) and world.vehicle.armed
    assert world.session.phase_text() == "flying in ALTCTL"


class WavingSticks(TimedSticks):
    """The right stick never rests: a different value on every poll."""

    def poll(self, timeout_s: float) -> StickCommand:
        self.polls += 1
        return StickCommand(up=0.0, right=0.01 * (self.polls % 7)) if self.clock.now() > 9.0 else CENTRE


def test_manual_control_streams_at_the_rate_whatever_the_sticks_do() -> None:
    world = airborne()
    world.session.sticks = WavingSticks(world.clock, [])
    before = len(world.manual())
    world.run_until(18.0)
    assert 10 * 25 * 0.97 <= len(world.manual()) - before <= 10 * 25 * 1.03  # steady: stick changes wait for a tick
    gaps = [b - a for (a, _), (b, _) in zip(world.manual(8.0), world.manual(8.0)[1:], strict=False)]
    assert max(gaps) < 0.05  # never near PX4's COM_RC_LOSS_T (0.5 s)


def test_throttle_takes_off_centred_holds_and_sticks_fly_north_and_east() -> None:
    world = airborne([(9.0, StickCommand(up=0.0, forward=0.5)), (10.0, CENTRE), (12.0, StickCommand(up=0.0, right=0.5)),
                      (13.0, CENTRE)])
    z0 = world.vehicle.pos[2]
    world.run_until(11.5)
    x1, y1, z1 = world.vehicle.pos
    assert x1 > 1.5 and abs(y1) < 0.2 and z1 == pytest.approx(z0, abs=0.3)
    world.run_until(16.0)
    x2, y2, _ = world.vehicle.pos
    assert y2 > 1.5 and abs(x2 - x1) < 0.2
    sent = [m for _, m in world.manual(9.1) if m.x > 0]
    assert sent and max(m.x for m in sent) == 500


def test_a_throttle_held_up_while_arming_does_not_take_off_until_centred() -> None:
    world = make_world([(0.0, UP), (8.0, CENTRE), (9.0, UP)])
    world.run_until(7.9)
    assert world.vehicle.armed and world.vehicle.pos[2] == 0.0
    assert all(m.z == 500 for _, m in world.manual())  # armed with z 500 <= 600, and held there
    world.run_until(12.0)
    assert world.vehicle.pos[2] < -2.0  # once centred, the throttle flies


class UpOnceArmed(TimedSticks):
    """A quick pilot: the throttle goes up the moment the vehicle is armed, before joyfly's 1 Hz HEARTBEAT says so."""

    def __init__(self, clock: SimClock, vehicle: ManualFakeVehicle) -> None:
        super().__init__(clock, [])
        self.vehicle = vehicle

    def poll(self, timeout_s: float) -> StickCommand:
        return UP if self.vehicle.armed else CENTRE


def test_a_throttle_pushed_as_soon_as_the_vehicle_arms_takes_off() -> None:
    world = make_world()
    world.session.sticks = UpOnceArmed(world.clock, world.vehicle)
    world.run_until(8.0)
    assert world.vehicle.pos[2] < -1.0, world.notes()  # the interlock opened with the stick centred at arming


def test_the_arming_refusal_is_reported_with_the_vehicles_reason() -> None:
    world = make_world()
    world.vehicle.refuse_arm_reason = "Arming denied: Resolve system health failures first"
    world.run_until(20.0)
    assert world.session.phase is Phase.FAILED and len(world.commands(400)) == 3
    assert "Arming denied: Resolve system health failures first" in (world.session.error or "")


def test_the_fence_and_max_alt_stop_full_sticks() -> None:
    world = airborne([(9.0, StickCommand(up=1.0, right=1.0))], fence_m=5.0, max_alt_m=8.0)
    world.run_until(30.0)
    assert max(abs(p[1]) for _, _, p in world.trace) < 5.0 and world.vehicle.pos[1] > 3.5
    assert max(-p[2] for _, _, p in world.trace) < 8.0 and -world.vehicle.pos[2] > 6.5
    assert world.session.stats.min_fence_margin_m > 0.0


def test_joystick_lost_holds_in_loiter_then_lands_with_centred_sticks() -> None:
    world = airborne([*sweeping(9.0, 9.5), (9.5, StickCommand(connected=False))], joy_timeout_s=4.0)
    world.run_until(10.0)
    hold = [(t, m) for t, m in world.commands(176) if (m.param2, m.param3) == (4, 3)]
    assert hold and hold[0][1].param1 == 1 | 128 and world.vehicle.custom_mode == LOITER
    assert all((m.x, m.y, m.z) == (0, 0, 500) for _, m in world.manual(hold[0][0] - 0.28))  # steady first
    assert "Pilot took over" not in "\n".join(world.vehicle.texts)
    assert "Joystick lost: Hold (AUTO.LOITER)" in world.notes() and not world.commands(21)
    world.run_until(13.6)
    assert world.commands(21) and world.commands(21)[0][0] == pytest.approx(13.5, abs=0.15)
    world.run_until(30.0)
    assert not world.vehicle.armed and world.session.phase is Phase.DONE
    lost = [m for t, m in world.manual(9.6)]
    assert lost and all((m.x, m.y, m.z, m.r) == (0, 0, 500, 0) for m in lost)
    assert_stream_stopped_at_the_end(world)


def test_joystick_back_before_the_timeout_takes_posctl_again() -> None:
    world = airborne([(9.0, StickCommand(connected=False)), (11.0, CENTRE)], joy_timeout_s=5.0)
    world.run_until(16.0)
    assert "Joystick back" in world.notes() and not world.commands(21)
    assert world.session.phase is Phase.FLYING and world.vehicle.custom_mode == POSCTL


def sweeping(start_s: float, end_s: float) -> list[tuple[float, StickCommand]]:
    """The right stick swept to and fro, each 0.04 s a new deflection: PX4 sees sticks on the move."""
    n = round((end_s - start_s) / 0.04)
    return [(start_s + 0.04 * i, StickCommand(up=0.0, right=0.8 * abs((i % 10) - 5) / 5)) for i in range(n)]


def test_ctrl_c_lands_with_centred_sticks_streams_until_disarmed_then_stops() -> None:
    world = airborne(sweeping(9.0, 12.0))
    world.run_until(11.9)
    world.session.request_exit()  # while the sticks move: PX4 must not take the landing back to Position mode
    world.run_until(40.0)
    assert world.session.phase is Phase.DONE and world.commands(21) and not world.vehicle.armed
    land_t = world.commands(21)[0][0]
    assert land_t > 11.9 + 0.3 and all((m.x, m.y, m.z) == (0, 0, 500) for _, m in world.manual(land_t - 0.3))
    assert "Pilot took over" not in "\n".join(world.vehicle.texts)
    assert_stream_stopped_at_the_end(world)
    assert world.vehicle.failsafe_since is None and "Failsafe" not in world.notes()


def test_exit_with_hold_warns_that_px4_returns_once_the_stream_stops() -> None:
    world = airborne(on_exit="hold")
    world.session.request_exit()
    world.run_until(12.0)
    assert world.session.phase is Phase.DONE and world.vehicle.custom_mode == LOITER
    assert "returns home (NAV_RCL_ACT)" in world.notes()


def test_a_link_outage_stops_the_stream_and_px4s_failsafe_is_not_fought() -> None:
    world = airborne([(16.0, press(Action.OFFBOARD)), (16.3, CENTRE)])
    world.vehicle.speak = False
    world.run_until(12.5)
    assert "Link lost" in world.notes()
    count = len(world.manual())
    world.run_until(14.0)
    assert len(world.manual()) == count  # nothing sent while the vehicle is not heard
    world.vehicle.speak = True
    world.run_until(15.9)
    assert "Link back" in world.notes() and world.session.phase is Phase.PAUSED
    assert "after the outage (PX4's failsafe for the lost MANUAL_CONTROL)" in world.notes()
    world.run_until(19.0)
    assert world.session.phase is Phase.FLYING and world.vehicle.custom_mode == POSCTL


def test_moving_the_sticks_in_hold_takes_control_back_as_px4_hands_it() -> None:
    push = [(11.0 + 0.05 * i, StickCommand(up=0.0, forward=0.2 * i)) for i in range(1, 5)]  # a push, not a jump
    world = airborne([(9.0, press(Action.HOLD)), (9.3, CENTRE), *push])
    world.run_until(10.5)
    assert world.session.phase is Phase.PAUSED and world.vehicle.custom_mode == LOITER
    world.run_until(12.5)
    assert world.session.phase is Phase.FLYING and "again (the sticks took over" in world.notes()


def test_land_and_return_buttons_use_px4s_auto_modes() -> None:
    world = airborne([(9.0, press(Action.RETURN)), (9.3, CENTRE)])
    world.run_until(9.6)
    assert world.vehicle.custom_mode == RTL and world.session.phase is Phase.LANDING
    world = airborne([(9.0, press(Action.LAND)), (9.3, CENTRE)])
    world.run_until(30.0)
    assert world.vehicle.custom_mode in (LAND, LOITER) and not world.vehicle.armed
    assert world.session.phase is Phase.GROUNDED


def test_taking_over_a_vehicle_flying_in_posctl() -> None:
    world = make_world([(0.0, UP), (3.0, CENTRE), (4.0, StickCommand(up=0.0, forward=0.5))])
    v = world.vehicle
    v.pos, v.landed, v.armed, v.custom_mode, v.intention = [1.0, 0.0, -4.0], False, True, POSCTL, POSCTL
    v.manual_time = 0.0
    world.run_until(2.0)
    assert world.session.phase is Phase.FLYING and "already flying in POSCTL" in world.notes()
    assert all(m.z == 500 for _, m in world.manual())  # the throttle up at the start does nothing (interlock)
    world.run_until(6.0)
    assert v.pos[0] > 2.0


def test_the_view_and_the_summary_show_the_sticks_sent_and_the_vehicles_answer() -> None:
    world = airborne([(9.0, StickCommand(up=0.2, forward=0.3, yaw=-0.1))])
    world.run_until(9.5)
    text = "\n".join(render(world.session.view()))
    for expected in ("flying in POSCTL", "mode POSCTL", "ARMED", "MANUAL_CONTROL streaming",
                     "sticks sent  x  +300 y    +0 z  600 r  -100", "alt "):
        assert expected in text, text
    lines = summary_lines(world.session.stats, world.session.control_label(), world.session.summary_extra())
    summary = "\n".join(lines)
    assert "time in POSCTL" in summary and "Position mode (POSCTL), MANUAL_CONTROL at 25 Hz" in summary
    assert "last sticks sent      x  +300" in summary and "vehicle at the end    POSCTL, armed" in summary
    assert lines[-1].startswith("highest")
    assert world.session.stats.control_time_s > 4.0


def test_quitting_at_once_says_px4s_rc_loss_failsafe_takes_over() -> None:
    world = airborne()
    assert "manual-control-loss failsafe holds it for COM_FAIL_ACT_T (5 s)" in left_behind(world.session)
    assert "left armed in POSCTL" in left_behind(world.session)


def test_a_vehicle_blown_out_of_the_fence_in_position_mode_is_warned_and_landed_after_the_grace() -> None:
    world = airborne(fence_m=5.0)
    world.vehicle.wind_m_s = (8.0, 0.0)  # PX4's Position mode holds where the sticks leave it; this wind wins
    world.run_until(20.0)
    out = [n for n in world.session.notes if "m outside the fence (5 m around home)" in n.text]
    assert len(out) == 1 and out[0].level.name == "WARN", world.notes()
    land = world.commands(21)
    assert land and out[0].time_s + 4.9 < land[0][0] < out[0].time_s + 5.3
    assert "landing where it is (--fence-action land)" in world.notes()
    assert world.session.stats.fence_breaches == 1
    assert "fence breached        once" in "\n".join(summary_lines(world.session.stats))
