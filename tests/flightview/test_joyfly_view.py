"""joyfly's browser view: what it takes from the session and the link, how often it logs, and that the terminal
view still gets everything; a real Rerun recording (a .rrd file, no viewer) when the extra is installed."""

from __future__ import annotations

import math
import subprocess
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace
from typing import Any

from support.view_process import require_rerun

from flightview.launch import ViewHandle, ViewOptions, open_view
from flightview.scene import FenceBox, Frame
from joyfly.session.core import FlightStats, Phase, SessionView
from joyfly.sticks.setpoints import Fence, Setpoint
from joyfly.types import StickCommand
from joyfly.view import VEHICLE_KEY, BrowserView


class RecordingLive:
    """Stands in for flightview's LiveView: keeps what it was given."""

    def __init__(self, due_every: int = 1) -> None:
        self.frames: list[Frame] = []
        self.fences: list[FenceBox | None] = []
        self.calls = 0
        self.due_every = due_every

    def due(self) -> bool:
        self.calls += 1
        return self.calls % self.due_every == 0

    def log(self, key: str, frame: Frame) -> None:
        assert key == VEHICLE_KEY
        self.frames.append(frame)

    def fence(self, box: FenceBox | None) -> None:
        self.fences.append(box)

    def end_frame(self) -> None:
        pass

    def close(self) -> None:
        pass


class Inner:
    def __init__(self) -> None:
        self.shown: list[SessionView] = []
        self.closed: bool | None = None

    def note(self, note: Any) -> None:
        pass

    def show(self, view: SessionView) -> None:
        self.shown.append(view)

    def close(self, keep: bool = True) -> None:
        self.closed = keep


def session_view(**changes: Any) -> SessionView:
    view = SessionView(time_s=3.0, phase=Phase.FLYING, link_ok=True, mode="OFFBOARD", armed=True, landed_state=2,
                       pos_ned_m=(1.0, 2.0, -3.0), setpoint=Setpoint((1.5, 2.0, -3.0), 0.0),
                       streaming=True, stick=StickCommand(forward=0.5, right=-0.25, up=None, yaw=0.1,
                                                          throttle_abs=0.75),
                       joystick_ok=True, fence=Fence(), stats=FlightStats(), statustexts=(), notes=(),
                       link_description="test")
    return replace(view, **changes)


def browser_view(live: Any, inner: Inner | None = None) -> tuple[BrowserView, Any]:
    link = SimpleNamespace(on_message=[], state=SimpleNamespace(home_ned_m=(0.0, 0.0, 0.5)))
    handle = ViewHandle(live, None)
    return BrowserView(inner or Inner(), handle, link), link


def message(kind: str, **fields: float) -> Any:
    return SimpleNamespace(get_type=lambda: kind, **fields)


def test_a_frame_has_what_joyfly_hears_and_sends() -> None:
    live = RecordingLive()
    view, link = browser_view(live)
    for observer in link.on_message:
        observer(message("ATTITUDE", roll=0.0, pitch=0.0, yaw=math.pi / 2))
    view.show(session_view())
    frame = live.frames[0]
    assert frame.pos_ned_m == (1.0, 2.0, -3.0)
    assert frame.setpoint_ned_m == (1.5, 2.0, -3.0)
    assert frame.home_ned_m == (0.0, 0.0, 0.5)
    assert frame.q_wxyz is not None and math.isclose(frame.q_wxyz[3], math.sin(math.pi / 4))
    assert frame.sticks == (0.5, -0.25, 0.5, 0.1)  # a radio's throttle 0.75 is +0.5 on the -1..1 scale
    assert (frame.mode, frame.armed, frame.time_s) == ("OFFBOARD", True, 3.0)
    assert live.fences == [FenceBox((0.0, 0.0, 0.0), 5.0, 0.5, 10.0)]


def test_without_a_setpoint_of_its_own_it_shows_the_vehicles_target() -> None:
    live = RecordingLive()
    view, link = browser_view(live)
    link.on_message[0](message("POSITION_TARGET_LOCAL_NED", x=4.0, y=5.0, z=-6.0))
    view.show(session_view(setpoint=None, mode="POSCTL"))
    link.on_message[0](message("POSITION_TARGET_LOCAL_NED", x=math.nan, y=math.nan, z=-6.0))
    view.show(session_view(setpoint=None, mode="ALTCTL"))
    assert [f.setpoint_ned_m for f in live.frames] == [(4.0, 5.0, -6.0), None]


def test_every_view_reaches_the_terminal_but_only_due_ones_are_logged() -> None:
    live, inner = RecordingLive(due_every=4), Inner()
    view, _ = browser_view(live, inner)
    for _ in range(12):
        view.show(session_view())
    assert len(inner.shown) == 12
    assert len(live.frames) == 3
    assert len(live.fences) == 1  # logged again only when it changes
    view.close(keep=False)
    assert inner.closed is False


def test_the_real_view_records_a_flight_to_a_file(tmp_path: Path) -> None:
    require_rerun()
    record = tmp_path / "joyfly.rrd"
    handle = open_view("joyfly", [VEHICLE_KEY], ViewOptions(record=record), lambda line: None)
    assert handle is not None and handle.server is None  # --record-view alone: no viewer, no port
    view, _ = browser_view(handle.live)
    view.handle = handle
    for i in range(60):
        handle.live._next_wall_s = 0.0  # every frame due: the test does not wait for the wall clock
        view.show(session_view(time_s=i * 0.1, pos_ned_m=(0.1 * i, 0.0, -3.0)))
    view.close()
    from flightview.server import rerun_program

    printed = subprocess.run([rerun_program(), "rrd", "print", str(record)], capture_output=True, text=True,
                             timeout=60, check=True).stdout
    for entity in ("/world/vehicle/body", "/world/vehicle/trail", "/world/fence", "/plots/north/vehicle",
                   "/plots/sticks/vehicle", "/modes/vehicle"):
        assert entity in printed, entity
