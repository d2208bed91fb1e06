"""The flight session in simulated time against a fake PX4 over an in-memory MAVLink link.

Each test flies a whole scenario (seconds of simulated flight in milliseconds of CPU) and checks what a user would
notice: where the vehicle went, what joyfly said, which messages it sent in which order.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import pytest
from support.joyfly_fakes import LAND, LOITER, OFFBOARD, RTL, FakeVehicle, TimedSticks
from support.joyfly_sim import SimClock, memory_pair

from joyfly.dashboard import render
from joyfly.link.vehicle_link import VehicleLink
from joyfly.session.flight_session import FlightSession, Phase, SessionSettings
from joyfly.types import Action, StickCommand


@dataclass
class World:
    clock: SimClock
    vehicle: FakeVehicle
    session: FlightSession
    sticks: TimedSticks
    trace: list[tuple[float, Phase, tuple[float, float, float] | None]] = field(default_factory=list)

    def run_until(self, t_s: float) -> None:
        while self.clock.now() < t_s and not self.session.finished:
            self.session.run_once()
            self.trace.append((self.clock.now(), self.session.phase, self.vehicle_pos()))

    def vehicle_pos(self) -> tuple[float, float, float]:
        x, y, z = self.vehicle.pos
        return (x, y, z)

    def notes(self) -> str:
        return "\n".join(n.text for n in self.session.notes)


def make_world(steps: list[tuple[float, StickCommand]] | None = None, **settings: object) -> World:
    clock = SimClock(max_step_s=0.005)
    ours, theirs = memory_pair()
    vehicle = FakeVehicle(theirs)
    clock.on_advance(vehicle.step)
    sticks = TimedSticks(clock, steps or [(0.0, StickCommand())])
    session = FlightSession(VehicleLink(ours, clock), sticks, clock, SessionSettings(**settings))  # type: ignore[arg-type]
    return World(clock, vehicle, session, sticks)


def airborne(extra: list[tuple[float, StickCommand]] | None = None, **settings: object) -> World:
    world = make_world([(0.0, StickCommand()), *(extra or [])], **settings)
    world.run_until(6.0)
    assert world.session.phase is Phase.FLYING, world.notes()
    return world


def test_offboard_entry_follows_the_seed_order_setpoints_then_arm_then_offboard() -> None:
    world = airborne()
    setpoints = world.vehicle.received("SETPOINT")
    arm = world.vehicle.received("CMD400")
    mode = world.vehicle.received("CMD176")
    assert arm and mode
    assert sum(1 for t, _ in setpoints if t < arm[0][0]) >= 10
    assert arm[0][0] < mode[0][0]
    assert (mode[0][1].param2, mode[0][1].param1 % 2) == (6, 1)  # OFFBOARD main mode, custom-mode flag
    assert world.vehicle.custom_mode == OFFBOARD and world.vehicle.armed
    assert world.vehicle.pos[2] == pytest.approx(-3.0, abs=0.2)  # --alt 3 m above home


def test_joyfly_heartbeats_as_a_gcs_at_1_hz_from_255_190() -> None:
    world = airborne()
    beats = world.vehicle.received("HEARTBEAT")
    assert beats and all(b == (6, 8, 255, 190) for _, b in beats)
    assert len(beats) == pytest.approx(6, abs=1)


def test_setpoints_stream_at_the_rate_whatever_the_sticks_do() -> None:
    world = airborne(rate_hz=20.0)
    before = len(world.vehicle.received("SETPOINT"))
    world.run_until(16.0)
    assert len(world.vehicle.received("SETPOINT")) - before >= 10 * 20 * 0.95


def test_stick_forward_flies_north_and_right_flies_east() -> None:
    world = airborne([(7.0, StickCommand(forward=0.5)), (8.0, StickCommand()),
                      (12.0, StickCommand(right=0.5)), (13.0, StickCommand())])
    world.run_until(11.5)
    x1, y1, _ = world.vehicle_pos()
    assert x1 > 1.5 and abs(y1) < 0.2
    world.run_until(17.0)
    x2, y2, _ = world.vehicle_pos()
    assert y2 > 1.5 and abs(x2 - x1) < 0.2


def test_releasing_the_sticks_holds_position() -> None:
    world = airborne([(7.0, StickCommand(forward=-0.6, right=0.3)), (8.5, StickCommand())])
    world.run_until(10.0)
    settled = world.vehicle_pos()
    world.run_until(20.0)
    drift = max(abs(a - b) for a, b in zip(world.vehicle_pos(), settled, strict=True))
    assert drift < 0.5


def test_pushing_against_the_fence_never_crosses_it() -> None:
    world = airborne([(7.0, StickCommand(forward=1.0, right=1.0)), (17.0, StickCommand(right=-1.0))],
                     fence_m=4.0)
    world.run_until(27.0)
    worst = max(max(abs(p[0]), abs(p[1])) for _, _, p in world.trace if p is not None)
    assert 3.5 < worst <= 4.0 + 0.5
    assert world.session.stats.min_fence_margin_m > -0.5


def test_arming_refusal_prints_the_vehicles_reason() -> None:
    world = make_world()
    world.vehicle.refuse_arm_reason = "Arming denied: Resolve system health failures first"
    world.run_until(20.0)
    assert world.session.phase is Phase.FAILED
    assert "TEMPORARILY_REJECTED" in world.notes()
    assert "Arming denied: Resolve system health failures first" in (world.session.error or "")
    assert len(world.vehicle.received("CMD400")) == 3  # bounded retries
    assert not world.vehicle.received("CMD176")


def test_lost_joystick_holds_then_lands_after_the_timeout() -> None:
    world = airborne([(7.0, StickCommand(forward=1.0)), (7.6, StickCommand(forward=1.0, connected=False))],
                     joy_timeout_s=5.0)
    world.run_until(8.0)
    assert "Joystick lost" in world.notes()
    world.run_until(11.5)
    held = world.vehicle_pos()
    world.run_until(12.4)
    assert not world.vehicle.received("CMD21")
    assert max(abs(a - b) for a, b in zip(world.vehicle_pos(), held, strict=True)) < 0.3
    world.run_until(13.0)
    assert world.vehicle.received("CMD21") and world.vehicle.received("CMD21")[0][0] == pytest.approx(12.6, abs=0.2)
    world.run_until(25.0)
    assert not world.vehicle.armed and world.session.phase is Phase.DONE  # landed, disarmed, no joystick: done
    assert "The joystick is gone and the vehicle is on the ground, disarmed" in world.notes()


def test_joystick_back_before_the_timeout_cancels_the_landing() -> None:
    world = airborne([(7.0, StickCommand(connected=False)), (9.0, StickCommand())], joy_timeout_s=5.0)
    world.run_until(15.0)
    assert "Joystick back" in world.notes()
    assert not world.vehicle.received("CMD21") and world.session.phase is Phase.FLYING


def test_failsafe_out_of_offboard_is_reported_and_not_fought() -> None:
    world = airborne()
    world.vehicle.failsafe(RTL)
    world.run_until(8.0)
    assert world.session.phase is Phase.PAUSED
    assert "left OFFBOARD for AUTO.RTL" in world.notes() and "Failsafe activated" in world.notes()
    sent = len(world.vehicle.received("SETPOINT"))
    modes = len(world.vehicle.received("CMD176"))
    world.run_until(12.0)
    assert len(world.vehicle.received("SETPOINT")) == sent
    assert len(world.vehicle.received("CMD176")) == modes
    assert world.vehicle.custom_mode != OFFBOARD  # RTL took it home and landed it


def test_offboard_button_takes_control_back_after_a_failsafe() -> None:
    press = StickCommand(pressed=frozenset({Action.OFFBOARD}))
    world = airborne([(9.0, press), (9.3, StickCommand())])
    world.vehicle.failsafe(LOITER)
    world.run_until(8.5)
    assert world.session.phase is Phase.PAUSED
    world.run_until(12.0)
    assert world.session.phase is Phase.FLYING and world.vehicle.custom_mode == OFFBOARD


def test_land_button_lands_and_stops_commanding() -> None:
    press = StickCommand(pressed=frozenset({Action.LAND}))
    world = airborne([(7.0, press), (7.3, StickCommand())])
    world.run_until(8.0)
    assert world.vehicle.custom_mode == LAND
    world.run_until(20.0)
    assert world.session.phase is Phase.GROUNDED and not world.vehicle.armed


def test_exit_request_lands_disarms_and_finishes() -> None:
    world = airborne()
    world.session.request_exit()
    world.run_until(30.0)
    assert world.session.phase is Phase.DONE
    assert world.vehicle.received("CMD21") and not world.vehicle.armed
    assert world.vehicle.pos[2] == pytest.approx(0.0)


def test_a_long_link_loss_is_said_again_every_30_s_so_the_wait_does_not_look_like_a_hang() -> None:
    world = airborne()
    world.vehicle.speak = False
    world.run_until(75.0)
    reminders = [n for n in world.notes().splitlines() if n.startswith("Still no HEARTBEAT after")]
    assert len(reminders) == 2 and "keeps trying" in reminders[0] and "Ctrl-C quits" in reminders[0]


def test_exit_with_hold_leaves_the_vehicle_holding() -> None:
    world = airborne(on_exit="hold")
    world.session.request_exit()
    world.run_until(10.0)
    assert world.session.phase is Phase.DONE
    assert world.vehicle.custom_mode == LOITER and world.vehicle.armed


def test_link_loss_is_reported_and_the_stream_resumes_when_the_vehicle_is_back() -> None:
    world = airborne()
    world.vehicle.speak = False
    world.run_until(10.5)
    assert "Link lost" in world.notes()
    world.vehicle.speak = True
    world.run_until(14.0)
    assert "Link back" in world.notes()
    assert world.session.phase is Phase.FLYING
    assert world.vehicle.received("SETPOINT")[-1][0] > 13.5


def test_no_vehicle_gives_a_clear_message() -> None:
    world = make_world(connect_timeout_s=3.0)
    world.vehicle.speak = False
    world.run_until(5.0)
    assert world.session.phase is Phase.FAILED
    assert "No HEARTBEAT from a vehicle on memory:a" in (world.session.error or "")
    assert "sitl-emu serve" in (world.session.error or "")


def test_summary_counts_distance_and_offboard_time() -> None:
    world = airborne([(7.0, StickCommand(forward=0.4)), (9.0, StickCommand())])
    world.run_until(12.0)
    stats = world.session.stats
    assert stats.distance_m > 3.0 + 3.0  # the climb plus ~4 m north
    assert stats.control_time_s == pytest.approx(12.0 - 2.5, abs=1.5)
    assert 0.0 < stats.min_fence_margin_m < 2.0


def test_sticks_off_centre_at_start_keep_the_vehicle_on_the_ground() -> None:
    world = make_world()
    problems = ["Axis 2 (up) reads +100% with the sticks untouched: centre the sticks."]
    world.sticks.rest_problems = lambda: problems  # type: ignore[attr-defined]
    world.run_until(5.0)
    assert world.session.phase is Phase.CONNECTING and not world.vehicle.received("CMD400")
    assert "Not taking off: Axis 2 (up) reads +100%" in world.notes()
    problems.clear()
    world.run_until(10.0)
    assert world.session.phase is Phase.FLYING


class JitterySticks(TimedSticks):
    """An axis that never rests: a different value on every poll."""

    def poll(self, timeout_s: float) -> StickCommand:
        self.polls += 1
        return StickCommand(right=0.001 * (self.polls % 7))


def test_a_jittery_axis_does_not_flood_the_vehicle_with_setpoints() -> None:
    clock = SimClock(max_step_s=0.005)
    ours, theirs = memory_pair()
    vehicle = FakeVehicle(theirs)
    clock.on_advance(vehicle.step)
    session = FlightSession(VehicleLink(ours, clock), JitterySticks(clock, []), clock, SessionSettings())
    end = 12.0
    while clock.now() < end and not session.finished:
        session.run_once()
    assert session.phase is Phase.FLYING
    rate = sum(1 for t, _ in vehicle.received("SETPOINT") if t > 8.0) / (end - 8.0)
    assert 50 <= rate <= 121  # stick changes go out at once, at most 100 times a second, plus the 20 Hz stream


def test_a_vehicle_left_in_return_mode_is_switched_to_hold_before_arming() -> None:
    world = make_world()
    world.vehicle.custom_mode = world.vehicle.intention = RTL
    world.run_until(8.0)
    assert world.session.phase is Phase.FLYING, world.notes()
    assert "from AUTO.RTL to Hold before arming" in world.notes()
    hold = [m for _, m in world.vehicle.received("CMD176") if (m.param2, m.param3) == (4, 3)]
    assert hold and hold[0] is world.vehicle.received("CMD176")[0][1]


def test_a_vehicle_that_will_not_hold_is_still_asked_to_arm_and_its_refusal_shown() -> None:
    world = make_world()
    world.vehicle.custom_mode = world.vehicle.intention = LAND
    world.vehicle._set_mode = lambda msg, mode: world.vehicle._ack(msg, 1)  # type: ignore[method-assign]
    world.run_until(15.0)
    assert len([m for _, m in world.vehicle.received("CMD176")]) == 2
    assert world.session.phase is Phase.FAILED
    assert "Arming denied: mode not armable" in (world.session.error or "")


def test_a_vehicle_disarmed_under_us_stops_the_stream() -> None:
    world = airborne()
    world.vehicle.armed = False  # a kill switch from another ground station; PX4 stays in OFFBOARD
    world.run_until(8.0)
    assert world.session.phase is Phase.GROUNDED and "The vehicle disarmed" in world.notes()
    sent = len(world.vehicle.received("SETPOINT"))
    world.run_until(10.0)
    assert len(world.vehicle.received("SETPOINT")) == sent


def test_the_fence_is_centred_where_the_vehicle_takes_off_not_on_an_old_home() -> None:
    world = make_world(fence_m=2.0)
    world.vehicle.pos = [3.0, -1.0, 0.0]  # landed away from its home of an earlier flight (still (0, 0, 0))
    world.run_until(10.0)
    assert world.session.phase is Phase.FLYING, world.notes()
    assert world.session.fence.home_ned_m == pytest.approx((3.0, -1.0, 0.0))
    assert world.vehicle.pos[:2] == pytest.approx([3.0, -1.0], abs=0.2)  # climbed straight up, no slide
    assert world.session.stats.min_fence_margin_m > 1.5


def test_taking_over_a_flying_vehicle_centres_the_fence_on_its_home() -> None:
    world = make_world(fence_m=4.0)
    v = world.vehicle
    v.home, v.pos, v.landed, v.armed = [10.0, 5.0, 0.0], [11.0, 5.0, -3.0], False, True
    v.custom_mode = v.intention = LOITER
    world.run_until(3.0)
    assert world.session.phase is Phase.PAUSED, world.notes()
    assert world.session.fence.home_ned_m == pytest.approx((10.0, 5.0, 0.0))


def test_a_script_joystick_that_ends_after_landing_finishes_the_session() -> None:
    press = StickCommand(pressed=frozenset({Action.LAND}))
    world = airborne([(7.0, press), (7.3, StickCommand()), (9.0, StickCommand(connected=False))])
    world.run_until(9.5)
    assert world.session.phase is Phase.LANDING
    assert "(holding)" not in "\n".join(render(world.session.view()))
    world.run_until(40.0)
    assert world.session.phase is Phase.DONE, world.notes()
    assert world.clock.now() < 25.0 and not world.vehicle.armed
    assert "The joystick is gone and the vehicle is on the ground, disarmed: joyfly is done." in world.notes()


def test_a_joystick_lost_in_flight_shows_holding_until_the_landing_starts() -> None:
    world = airborne([(7.0, StickCommand(connected=False))], joy_timeout_s=2.0)
    world.run_until(8.0)
    assert "LOST (holding)" in "\n".join(render(world.session.view()))
    world.run_until(9.5)
    assert world.session.phase is Phase.LANDING
    text = "\n".join(render(world.session.view()))
    assert "joystick LOST" in text and "(holding)" not in text


def test_a_restarted_vehicle_is_reported_as_restarted_and_not_armed_again() -> None:
    world = airborne()
    world.vehicle.speak = False
    world.run_until(11.0)
    assert "Link lost" in world.notes()
    world.vehicle.reboot()
    world.vehicle.speak = True
    world.run_until(20.0)
    notes = world.notes()
    assert "The vehicle restarted" in notes and "went back" in notes and "Link back" not in notes
    assert "will not arm it again" in notes
    assert world.session.phase is Phase.GROUNDED
    assert not [t for t, _ in world.vehicle.received("CMD400") if t > 11.0] and not world.vehicle.armed
    assert world.session.stats.control_time_s == pytest.approx(6.0 - 1.05, abs=0.6)  # OFFBOARD at 1.05 s, not after


def test_a_link_outage_does_not_count_as_time_in_offboard() -> None:
    world = airborne()
    world.vehicle.speak = False
    world.run_until(16.0)
    world.vehicle.speak = True
    world.run_until(20.0)
    assert "Link back" in world.notes() and "restarted" not in world.notes()
    assert world.session.stats.control_time_s == pytest.approx(6.0 - 1.05 + 20.0 - 16.0, abs=0.6)  # 6 s to 16 s out


def test_ctrl_c_while_the_arm_command_is_on_its_way_does_not_leave_the_vehicle_armed() -> None:
    world = make_world()
    while not world.vehicle.received("CMD400") and world.clock.now() < 5.0:
        world.session.run_once()
    assert world.session.phase is Phase.ARMING and not world.session.link.state.armed
    asked_s = world.clock.now()
    world.session.request_exit()  # the ARM is accepted a moment later; the HEARTBEAT shows it up to 1 s after
    world.run_until(20.0)
    assert world.session.phase is Phase.DONE and not world.vehicle.armed
    # on the ground the exit disarms (issue 25.6): ARM_DISARM 0 after the ARM, and no LAND
    assert "Exiting: disarming on the ground" in world.notes() and not world.vehicle.received("CMD21")
    assert [round(m.param1) for t, m in world.vehicle.received("CMD400") if t >= asked_s][-1] == 0


def test_a_vehicle_restarted_before_joyfly_connected_is_simply_flown() -> None:
    world = make_world([(0.0, StickCommand(connected=False)), (4.0, StickCommand())])
    world.run_until(3.0)
    world.vehicle.reboot()  # its boot time goes back from 3 s to 0 while joyfly waits for the joystick
    world.run_until(12.0)
    assert world.session.phase is Phase.FLYING and "restarted" not in world.notes()


def _breach_notes(world: World) -> list[tuple[float, str]]:
    return [(n.time_s, n.text) for n in world.session.notes if "outside the fence" in n.text]


@pytest.mark.parametrize(("action", "command", "phase"), [("land", "CMD21", Phase.LANDING),
                                                          ("rtl", "CMD20", Phase.LANDING),
                                                          ("hold", "CMD176", Phase.PAUSED)])
def test_a_vehicle_blown_out_of_the_fence_is_warned_at_once_and_the_fence_action_follows(
        action: str, command: str, phase: Phase) -> None:
    world = airborne(fence_action=action)
    world.vehicle.wind_m_s = (0.0, 8.0)  # stronger than the fake's 5 m/s: it cannot come back
    world.run_until(9.0)
    (out_s, warning), = _breach_notes(world)
    assert 6.0 < out_s < 9.0
    assert f"--fence-action {action} acts if it stays outside for 5 s without coming back" in warning
    assert any(n.level.name == "WARN" and n.text == warning for n in world.session.notes)
    assert "BREACH" in "\n".join(render(world.session.view()))
    def sent() -> list[float]:  # (DO_SET_MODE: to Hold, not OFFBOARD)
        return [t for t, m in world.vehicle.received(command) if command != "CMD176" or m.param3 == 3]

    assert not sent()
    world.run_until(out_s + 5.5)
    assert sent() and out_s + 4.9 < sent()[0] < out_s + 5.3, world.notes()
    assert world.session.phase is phase and "has been outside the fence for" in world.notes()
    assert world.session.stats.fence_breaches == 1 and world.session.stats.deepest_breach_m > 2.0


def test_fence_action_warn_only_warns_and_a_vehicle_that_comes_back_is_said_to_be_back() -> None:
    world = airborne(fence_action="warn")
    world.vehicle.wind_m_s = (0.0, 8.0)
    world.run_until(14.0)
    world.vehicle.wind_m_s = (0.0, 0.0)
    world.run_until(24.0)
    assert "joyfly only warns (--fence-action warn)" in world.notes()
    assert "The vehicle is back inside the fence." in world.notes()
    assert world.session.phase is Phase.FLYING and world.vehicle.custom_mode == OFFBOARD
    assert not world.vehicle.received("CMD21") and not world.vehicle.received("CMD20")
    assert world.session.stats.fence_breaches == 1


def test_a_gust_that_carries_the_vehicle_out_for_a_moment_is_said_but_not_acted_upon() -> None:
    world = airborne()  # --fence-action land, the default
    world.vehicle.wind_m_s = (0.0, 8.0)
    world.run_until(8.8)
    world.vehicle.wind_m_s = (0.0, 0.0)
    world.run_until(20.0)
    assert len(_breach_notes(world)) == 1 and "back inside" in world.notes()
    assert world.session.phase is Phase.FLYING and not world.vehicle.received("CMD21")


def test_pushing_against_the_fence_in_calm_air_is_no_breach() -> None:
    world = airborne([(7.0, StickCommand(forward=1.0, right=1.0)), (17.0, StickCommand())])
    world.run_until(20.0)
    assert world.session.stats.fence_breaches == 0 and not _breach_notes(world)


@pytest.mark.parametrize(("wind_after_m_s", "acts"), [(4.0, False), (4.9, True)])
def test_a_vehicle_on_its_way_back_is_let_come_back_and_one_the_wind_holds_outside_is_landed(
        wind_after_m_s: float, acts: bool) -> None:
    world = airborne()
    world.vehicle.wind_m_s = (0.0, 8.0)  # carried out, then a wind the fake (5 m/s at most) beats by 1 or 0.1 m/s
    world.run_until(9.5)
    world.vehicle.wind_m_s = (0.0, wind_after_m_s)
    world.run_until(14.0)
    alert = "\n".join(render(world.session.view()))
    world.run_until(30.0)
    land = world.vehicle.received("CMD21")
    if acts:
        (out_s, _), = _breach_notes(world)[:1]
        assert land and out_s + 4.9 < land[0][0] < out_s + 6.0, world.notes()
        assert "and is not coming back" in world.notes()
    else:
        assert "BREACH: coming back" in alert and "back inside the fence" in world.notes()
        assert not land and world.session.phase is Phase.FLYING


def test_a_breach_is_said_once_even_when_the_vehicles_position_pauses_during_it() -> None:
    world = airborne(fence_action="warn")
    world.vehicle.wind_m_s = (0.0, 8.0)
    world.run_until(10.0)
    world.vehicle.speak = False  # a second without telemetry: its position is stale, the link not yet lost
    world.run_until(11.0)
    world.vehicle.speak = True
    world.run_until(14.0)
    assert len([text for _, text in _breach_notes(world) if "m outside the fence (5 m" in text]) == 1, world.notes()
    assert world.session.stats.fence_breaches == 1
