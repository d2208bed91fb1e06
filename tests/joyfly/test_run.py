"""How `joyfly fly` ends (joyfly/run.py): Ctrl-C before a vehicle answered or before arming, a double Ctrl-C, and
the summary, each with a sentence that says what happened and in what state the vehicle was left. Real SIGINTs to
this process, a fake PX4 over an in-memory link, simulated time."""

from __future__ import annotations

import io
import os
import signal
from collections.abc import Callable
from typing import Any

from support.joyfly_fakes import FakeVehicle, TimedSticks
from support.joyfly_sim import SimClock, memory_pair

from joyfly.dashboard import LiveDashboard, PlainLog
from joyfly.link.vehicle_link import VehicleLink
from joyfly.run import fly_session
from joyfly.session.flight_session import FlightSession, SessionSettings, SessionView
from joyfly.types import StickCommand


class CtrlC:
    """A view that forwards to `inner` and sends this process a SIGINT at each of the given session times."""

    def __init__(self, inner: Any, at_s: list[float]) -> None:
        self.inner, self.at_s = inner, sorted(at_s)
        self.note: Callable[..., None] = inner.note

    def show(self, view: SessionView) -> None:
        self.inner.show(view)
        if self.at_s and view.time_s >= self.at_s[0]:
            self.at_s.pop(0)
            os.kill(os.getpid(), signal.SIGINT)

    def close(self, **kw: Any) -> None:
        self.inner.close(**kw)


def fly(ctrl_c_at_s: list[float], speak: bool = True, live: bool = False,
        **settings: Any) -> tuple[int, str, FakeVehicle]:
    clock = SimClock(max_step_s=0.005)
    ours, theirs = memory_pair()
    vehicle = FakeVehicle(theirs, speak=speak)
    clock.on_advance(vehicle.step)
    out = io.StringIO()
    view = CtrlC(LiveDashboard(out) if live else PlainLog(out), ctrl_c_at_s)
    session = FlightSession(VehicleLink(ours, clock), TimedSticks(clock, [(0.0, StickCommand())]), clock,
                            SessionSettings(**{"connect_timeout_s": 30.0, **settings}), on_note=view.note)
    status = fly_session(session, view, out)
    return status, out.getvalue(), vehicle


def test_ctrl_c_before_a_vehicle_answered_says_so_and_sums_up_nothing() -> None:
    status, out, _ = fly([2.0], speak=False)
    assert status == 0
    assert "Stopped before a vehicle answered on memory:a; nothing was flown." in out
    assert "distance flown" not in out


def test_ctrl_c_before_arming_says_nothing_was_flown() -> None:
    status, out, vehicle = fly([0.2])
    assert status == 0 and not vehicle.armed and not vehicle.received("CMD400")
    assert "Stopped before arming; nothing was flown (the vehicle is disarmed in AUTO.LOITER)." in out
    assert "distance flown" not in out


def test_a_double_ctrl_c_prints_the_view_once_and_names_the_state_the_vehicle_was_left_in(capsys: Any) -> None:
    """The closing sentence goes to stderr (README: the summary and a line on stderr say how joyfly ended)."""
    status, out, vehicle = fly([7.0, 7.5], live=True)
    err = capsys.readouterr().err
    assert status == 130
    final = out.split("\x1b[J")[-1]  # what stays on the terminal after the last redraw
    assert final.count("fence margin") == 1 and "interrupted twice" not in out
    assert err.count("interrupted twice") == 1 and len(err.splitlines()) == 1
    assert "the vehicle was left armed in AUTO.LAND" in err and vehicle.armed


class Events:
    """A view that forwards to `inner` and runs each (session time, action) once that time has come."""

    def __init__(self, inner: Any, events: list[tuple[float, Callable[[], None]]]) -> None:
        self.inner, self.events = inner, sorted(events, key=lambda e: e[0])
        self.note: Callable[..., None] = inner.note
        self.last: SessionView | None = None

    def show(self, view: SessionView) -> None:
        self.inner.show(view)
        self.last = view
        while self.events and view.time_s >= self.events[0][0]:
            self.events.pop(0)[1]()

    def close(self, **kw: Any) -> None:
        self.inner.close(**kw)


def _restart_in_flight(capsys: Any, start_ned_m: list[float]) -> tuple[int, str, str, Events]:
    """Take off where the vehicle stands, lose the link in the air, the vehicle restarts, Ctrl-C."""
    clock = SimClock(max_step_s=0.005)
    ours, theirs = memory_pair()
    vehicle = FakeVehicle(theirs, pos=list(start_ned_m))
    clock.on_advance(vehicle.step)
    out = io.StringIO()

    def link_back_restarted() -> None:
        vehicle.reboot()
        vehicle.speak = True

    view = Events(PlainLog(out), [(8.0, lambda: setattr(vehicle, "speak", False)), (14.0, link_back_restarted),
                                  (22.0, lambda: os.kill(os.getpid(), signal.SIGINT))])
    session = FlightSession(VehicleLink(ours, clock), TimedSticks(clock, [(0.0, StickCommand())]), clock,
                            SessionSettings(), on_note=view.note)
    status = fly_session(session, view, out)
    return status, out.getvalue(), capsys.readouterr().err, view


def test_a_vehicle_restarted_in_the_air_ends_the_flight_without_a_landing_exit_status_4(capsys: Any) -> None:
    status, out, err, _ = _restart_in_flight(capsys, [0.0, 0.0, 0.0])
    assert "The vehicle restarted" in out
    assert status == 4, out + err
    assert "landing               none: the vehicle restarted while it flew in OFFBOARD" in out
    assert out.rstrip().splitlines()[-1].startswith("highest")
    assert "joyfly: the flight ended without a landing: the vehicle restarted while it flew in OFFBOARD" in err


def test_after_a_restart_the_old_home_is_not_measured_against_the_new_frame(capsys: Any) -> None:
    _, out, _, view = _restart_in_flight(capsys, [20.0, 0.0, 0.0])  # took off 20 m north of the new frame's origin
    assert view.last is not None and view.last.pos_ned_m == (0.0, 0.0, 0.0)
    lines = out.split("The vehicle restarted")[1].splitlines()
    status_lines = [line for line in lines if "fence margin" in line]
    assert status_lines and all(line.endswith("fence margin -") for line in status_lines), "\n".join(lines)
    assert "OUTSIDE" not in out.split("The vehicle restarted")[1] and "fence breached" not in out


def test_a_flight_that_lands_exits_0_and_one_left_hovering_on_purpose_too(capsys: Any) -> None:
    status, out, _ = fly([8.0])  # Ctrl-C: --on-exit land
    assert status == 0 and "Landed and disarmed" in out and "landing               none" not in out
    status, out, vehicle = fly([8.0], on_exit="hold")
    assert status == 0 and "The vehicle holds position." in out and vehicle.armed and not vehicle.landed


def test_a_failure_is_said_once_on_stderr_not_also_in_the_view(capsys: Any) -> None:
    """The session's failure (here: no HEARTBEAT) was an ERROR line in the view and the closing line on stderr."""
    for live in (False, True):
        status, out, _ = fly([], speak=False, live=live, connect_timeout_s=1.0)
        err = capsys.readouterr().err
        assert status == 1 and "No HEARTBEAT" not in out, out
        assert err.count("No HEARTBEAT") == 1 and len(err.splitlines()) == 1, err
