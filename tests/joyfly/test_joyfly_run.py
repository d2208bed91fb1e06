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


def fly(ctrl_c_at_s: list[float], speak: bool = True, live: bool = False) -> tuple[int, str, FakeVehicle]:
    clock = SimClock(max_step_s=0.005)
    ours, theirs = memory_pair()
    vehicle = FakeVehicle(theirs, speak=speak)
    clock.on_advance(vehicle.step)
    out = io.StringIO()
    view = CtrlC(LiveDashboard(out) if live else PlainLog(out), ctrl_c_at_s)
    session = FlightSession(VehicleLink(ours, clock), TimedSticks(clock, [(0.0, StickCommand())]), clock,
                            SessionSettings(connect_timeout_s=30.0), on_note=view.note)
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


def test_a_double_ctrl_c_prints_the_view_once_and_names_the_state_the_vehicle_was_left_in() -> None:
    status, out, vehicle = fly([7.0, 7.5], live=True)
    assert status == 130
    final = out.split("\x1b[J")[-1]  # what stays on the terminal after the last redraw
    assert final.count("fence margin") == 1 and final.index("fence margin") < final.index("interrupted twice")
    assert out.count("interrupted twice") == 1
    assert "the vehicle was left armed in AUTO.LAND" in final and vehicle.armed
