"""`joyfly fly --view` and `joyfly demo --view`: the flight drawn live in the browser (the flightview package, Rerun),
from what joyfly hears over MAVLink, so it shows PX4 SITL or a real vehicle as well as the emulator.

BrowserView wraps the terminal view (dashboard.py): every SessionView still goes there, and at most
flightview.live.RATE_HZ of them a wall second become a Frame: the position, the setpoint joyfly sends (in PX4's
manual modes, the vehicle's own POSITION_TARGET_LOCAL_NED), home, the fence, the sticks, the mode and armed state;
the attitude comes from the vehicle's ATTITUDE messages (a link observer).
"""

from __future__ import annotations

import math
from typing import Any

from flightview.launch import ViewHandle, ViewOptions
from flightview.scene import FenceBox, Frame, euler_to_q
from flightview.server import ViewError
from joyfly.session.core import Note, SessionView
from joyfly.sticks.setpoints import Fence
from px4common.cli_style import UserError

VEHICLE_KEY = "vehicle"


class BrowserView:
    """The terminal view plus the live browser view; closing it closes both (and stops the viewer)."""

    def __init__(self, inner: Any, handle: ViewHandle, link: Any) -> None:
        self.inner = inner
        self.handle = handle
        self.link = link
        self.attitude_q: tuple[float, float, float, float] | None = None
        self.vehicle_target: tuple[float, float, float] | None = None
        self._fence: Fence | None = None
        link.on_message.append(self.observe)

    def observe(self, msg: Any) -> None:
        """A link observer: keep the attitude and the vehicle's position target (cheap: no logging here)."""
        kind = msg.get_type()
        if kind == "ATTITUDE":
            self.attitude_q = euler_to_q(msg.roll, msg.pitch, msg.yaw)
        elif kind == "POSITION_TARGET_LOCAL_NED":
            target = (float(msg.x), float(msg.y), float(msg.z))
            self.vehicle_target = None if any(math.isnan(c) for c in target) else target

    def note(self, note: Note) -> None:
        self.inner.note(note)

    def show(self, view: SessionView) -> None:
        self.inner.show(view)
        live = self.handle.live
        if not live.due():
            return
        if view.fence != self._fence:
            self._fence = view.fence
            live.fence(fence_box(view.fence))
        live.log(VEHICLE_KEY, self.frame(view))
        live.end_frame()

    def frame(self, view: SessionView) -> Frame:
        setpoint = view.setpoint.pos_ned_m if view.setpoint is not None else self.vehicle_target
        return Frame(time_s=view.time_s, pos_ned_m=view.pos_ned_m, q_wxyz=self.attitude_q, setpoint_ned_m=setpoint,
                     home_ned_m=self.link.state.home_ned_m, mode=view.mode, armed=view.armed,
                     sticks=stick_values(view))

    def close(self, keep: bool = True) -> None:
        try:
            self.inner.close(keep=keep)
        finally:
            self.handle.close()


def fence_box(fence: Fence) -> FenceBox | None:
    if not fence.enabled:
        return None
    return FenceBox(fence.home_ned_m, fence.half_width_m, fence.min_alt_m, fence.max_alt_m)


def stick_values(view: SessionView) -> tuple[float, float, float, float]:
    """forward, right, up, yaw in -1..1; a radio's throttle (0..1) shown as -1..1 like a centring stick."""
    s = view.stick
    up = s.up if s.up is not None else (2 * s.throttle_abs - 1 if s.throttle_abs is not None else 0.0)
    return (s.forward, s.right, up, s.yaw)


def check_view_options(options: ViewOptions) -> None:
    """Before anything opens: UserError in one sentence if the view cannot run (no extra, port in use...)."""
    from flightview.launch import check_view

    try:
        check_view(options)
    except ViewError as err:
        raise UserError(str(err)) from None


def add_browser_view(view: Any, session: Any, options: ViewOptions | None, out: Any) -> Any:
    """The terminal view, plus the browser's with --view / --record-view (joyfly/view.py); a problem starting it
    closes the link and the joystick and ends in one sentence."""
    if options is None or not options.wanted:
        return view
    from flightview.launch import open_view

    try:
        handle = open_view("joyfly", [VEHICLE_KEY], options, lambda line: out.write(f"joyfly: {line}\n"))
    except ViewError as err:
        session.link.close()
        session.sticks.close()
        raise UserError(str(err)) from None
    return view if handle is None else BrowserView(view, handle, session.link)
