"""The live view and the plain log: what a user reads while flying."""

from __future__ import annotations

import io
from dataclasses import replace

from joyfly.dashboard import LiveDashboard, PlainLog, bar, make_view, render, summary_lines
from joyfly.session.flight_session import FlightStats, Level, Note, Phase, SessionView
from joyfly.sticks.setpoints import Fence, Setpoint
from joyfly.types import Action, StickCommand


def view(t: float = 1.0, phase: Phase = Phase.FLYING, mode: str = "OFFBOARD", link_ok: bool = True,
         pos: tuple[float, float, float] | None = (4.5, -1.0, -3.0), streaming: bool = True) -> SessionView:
    return SessionView(
        time_s=t, phase=phase, link_ok=link_ok, mode=mode, armed=True, landed_state=2, pos_ned_m=pos,
        setpoint=Setpoint((4.8, -1.0, -3.0), 0.0, (1.0, 0.0, 0.0)), streaming=streaming,
        stick=StickCommand(forward=1.0, right=-0.5, pressed=frozenset({Action.LAND})), joystick_ok=True,
        fence=Fence((0.0, 0.0, 0.0), 5.0, 0.5, 10.0), stats=FlightStats(12.0, 0.3, 8.0, 3.0),
        statustexts=("Armed by external command", "Takeoff detected"), notes=(), link_description="UDP 0.0.0.0:14540")


def test_bar_shows_direction_and_size() -> None:
    assert bar(0.0) == "[     |     ]"
    assert bar(1.0) == "[     |#####]"
    assert bar(-0.4) == "[   ##|     ]"


def test_live_block_has_link_mode_position_setpoint_sticks_margin_and_texts() -> None:
    text = "\n".join(render(view()))
    for expected in ("link OK", "OFFBOARD", "ARMED", "+4.50", "+4.80", "fence margin +0.50 m", "buttons land",
                     "[     |#####]", "vehicle: Takeoff detected", "flying in OFFBOARD"):
        assert expected in text


def test_outside_the_fence_and_lost_link_stand_out() -> None:
    text = "\n".join(render(view(pos=(6.2, 0.0, -3.0), link_ok=False)))
    assert "OUTSIDE" in text and "link LOST" in text


def test_live_view_redraws_in_place_at_most_10_times_a_second() -> None:
    out = io.StringIO()
    live = LiveDashboard(out)
    for i in range(20):  # 20 views over one second
        live.show(view(t=i * 0.05))
    assert out.getvalue().count("\x1b[J") == 9  # 10 frames, each after the first erases the previous
    live.note(Note(1.0, Level.WARN, "Joystick lost"))
    assert "! Joystick lost\n" in out.getvalue()


def test_plain_log_prints_state_changes_and_at_most_one_line_a_second() -> None:
    out = io.StringIO()
    plain = PlainLog(out)
    for i in range(40):  # 2 s of flying at 20 Hz
        plain.show(view(t=i * 0.05))
    plain.show(view(t=2.0, phase=Phase.PAUSED, mode="AUTO.RTL", streaming=False))
    plain.note(Note(2.0, Level.WARN, "The vehicle left OFFBOARD"))
    lines = out.getvalue().splitlines()
    assert len(lines) == 4
    assert "AUTO.RTL" in lines[2] and "\x1b" not in out.getvalue()
    assert lines[3].endswith("WARNING The vehicle left OFFBOARD")


def test_make_view_picks_plain_lines_without_a_terminal() -> None:
    assert isinstance(make_view(io.StringIO()), PlainLog)
    assert isinstance(make_view(io.StringIO(), live=True), LiveDashboard)


def test_summary_reports_distance_fence_and_offboard_time() -> None:
    text = "\n".join(summary_lines(FlightStats(31.5, 0.8, 29.0, 4.1)))
    assert "31.5 m" in text and "closest to the fence  0.80 m inside" in text and "29.0 s" in text


def test_summary_words_a_breach_as_one_with_its_depth_and_an_overshoot_at_the_fence_as_none() -> None:
    breached = "\n".join(summary_lines(FlightStats(31.5, -32.9, 29.0, 4.1, fence_breaches=2, deepest_breach_m=32.9)))
    assert "fence breached        2 times, 32.90 m outside at the deepest" in breached
    assert "OUTSIDE" not in breached and "closest" not in breached
    overshoot = "\n".join(summary_lines(FlightStats(31.5, -0.004, 29.0, 4.1)))
    assert "closest to the fence  0.00 m past it, within joyfly's 1 m tolerance: no breach" in overshoot
    assert "OUTSIDE" not in overshoot and "breached" not in overshoot


def test_the_live_block_shows_a_breach_and_the_time_before_the_fence_action() -> None:
    text = "\n".join(render(replace(view(pos=(12.0, 0.0, -3.0)), fence_alert="BREACH: land in 3 s")))
    assert "fence margin -7.00 m  BREACH: land in 3 s" in text
    assert "fence margin -0.20 m  on the fence" in "\n".join(render(view(pos=(5.2, 0.0, -3.0))))


def test_no_vehicle_yet_reads_waiting_not_lost_even_once_joyfly_stops() -> None:
    quiet = replace(view(phase=Phase.DONE, link_ok=False, pos=None), heard=False)
    assert "link waiting" in "\n".join(render(quiet))
    out = io.StringIO()
    PlainLog(out).show(quiet)
    assert "link waiting" in out.getvalue()
    assert "link LOST" in "\n".join(render(replace(quiet, heard=True)))


def test_a_lost_joystick_reads_holding_only_while_joyfly_holds_the_vehicle() -> None:
    lost = replace(view(), joystick_ok=False)
    assert "joystick LOST (holding)" in "\n".join(render(lost))
    for phase in (Phase.LANDING, Phase.GROUNDED, Phase.PAUSED, Phase.EXITING):
        text = "\n".join(render(replace(lost, phase=phase)))
        assert "joystick LOST" in text and "holding" not in text


def test_closing_the_live_view_takes_an_empty_block_away() -> None:
    out = io.StringIO()
    live = LiveDashboard(out)
    live.show(view(pos=None))
    live.close(keep=False)
    assert out.getvalue().endswith("\x1b[8F\x1b[J")
