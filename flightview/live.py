"""The live view: frames of vehicles logged to Rerun (the loopback viewer, a .rrd file, or both) at most RATE_HZ.

Layout: the 3D world on the left (Rerun's ground grid, the fence box, each vehicle's body, trail, setpoint and home),
plots on the right (north, east and altitude against the setpoint, the sticks once there are any, armed), and the
mode changes. One
frame costs about 1 ms of CPU in the Rerun SDK, so callers log from their own loop, never from a physics tick, and
`due()` keeps them at RATE_HZ of wall time whatever the simulation's speed.
"""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from flightview.scene import FenceBox, Frame, body_arms, fence_box, ned_to_enu
from flightview.server import ViewerServer, import_rerun

RATE_HZ = 25.0
TRAIL_POINTS = 1000  # the last 100 m flown
TRAIL_SPACING_M = 0.1  # a trail point every 10 cm moved: nothing piles up on the ground
TRAIL_EVERY = 10  # the trail (the longest thing logged) is sent at most every 10th frame (2.5 Hz), when it grew
AXES = (("north", 0), ("east", 1))
NAN = float("nan")
EYE_POSITION = (-10.0, -14.0, 9.0)  # the 3D view's first camera: south-west of home, above, looking at home
EYE_TARGET = (0.0, 0.0, 2.5)
STICKS = ("forward", "right", "up", "yaw")
PALETTE = [(255, 160, 0), (0, 170, 255), (120, 220, 80), (230, 80, 200), (255, 90, 90), (180, 180, 255)]
SETPOINT_COLOUR = (150, 150, 150)
HOME_COLOUR = (80, 255, 120)
FENCE_COLOUR = (255, 230, 0)
FRONT_COLOUR = (255, 40, 40)  # the vehicle's front arms (tests/flightview/test_browser.py looks for it)


class LiveView:
    """One Rerun recording fed with frames for the vehicles `keys` (e.g. "vehicle" or "sysid1", "sysid2"...)."""

    def __init__(self, app_id: str, keys: Sequence[str], server: ViewerServer | None = None,
                 record_path: Path | None = None) -> None:
        rr: Any = import_rerun()
        self.rr = rr
        self.keys = list(keys)
        self.rec = rr.RecordingStream(app_id)
        sinks = [rr.GrpcSink(server.grpc_url)] if server is not None else []
        if record_path is not None:
            sinks.append(rr.FileSink(str(record_path)))
        self._sticks_shown = False  # the sticks panel appears with the first sticks (none in OFFBOARD on serve's side)
        self.rec.set_sinks(*sinks, default_blueprint=self._blueprint())
        self._next_wall_s = 0.0
        self._trails: dict[str, deque[tuple[float, float, float]]] = {k: deque(maxlen=TRAIL_POINTS) for k in keys}
        self._modes: dict[str, tuple[str, bool]] = {}
        self._homes: dict[str, tuple[float, float, float] | None] = {}
        self._trail_sent: dict[str, int] = {}
        self._frames = 0
        self._log_static()

    def due(self) -> bool:
        """True at most RATE_HZ times a wall second: then log one frame per vehicle."""
        now = time.monotonic()
        if now < self._next_wall_s:
            return False
        self._next_wall_s = max(self._next_wall_s + 1.0 / RATE_HZ, now)
        return True

    def fence(self, box: FenceBox | None) -> None:
        """Draw the fence box (None: none)."""
        if box is None:
            self.rec.log("world/fence", self.rr.Clear(recursive=False), static=True)
            return
        centre, half = fence_box(box)
        self.rec.log("world/fence", self.rr.Boxes3D(centers=[centre], half_sizes=[half], colors=[FENCE_COLOUR],
                                                    fill_mode="majorwireframe"), static=True)

    def log(self, key: str, frame: Frame) -> None:
        """One vehicle's frame at its time."""
        rr, rec = self.rr, self.rec
        rec.set_time("flight_time", duration=frame.time_s)
        self._log_state(key, frame)
        if frame.pos_ned_m is not None:
            self._log_world(key, frame, frame.pos_ned_m)
            self._log_position_plots(key, frame, frame.pos_ned_m)
        if frame.sticks is not None:
            self._show_sticks_panel()
            rec.log(f"plots/sticks/{key}", rr.Scalars(frame.sticks))

    def end_frame(self) -> None:
        self._frames += 1

    def close(self) -> None:
        self.rec.flush()
        self.rec.disconnect()

    def _log_world(self, key: str, frame: Frame, pos: tuple[float, float, float]) -> None:
        rr, rec = self.rr, self.rec
        colour = self._colour(key)
        arms = body_arms(pos, frame.q_wxyz)
        colours = [FRONT_COLOUR, FRONT_COLOUR, colour, colour, (230, 230, 230)]
        rec.log(f"world/{key}/body", rr.LineStrips3D(arms, colors=colours, radii=[0.08]))
        self._log_trail(key, ned_to_enu(pos), colour)
        if frame.setpoint_ned_m is not None:
            rec.log(f"world/{key}/setpoint", rr.Points3D([ned_to_enu(frame.setpoint_ned_m)],
                                                         colors=[SETPOINT_COLOUR], radii=[0.15]))
        if frame.home_ned_m != self._homes.get(key, ()):
            self._homes[key] = frame.home_ned_m
            if frame.home_ned_m is not None:
                rec.log(f"world/{key}/home", rr.Points3D([ned_to_enu(frame.home_ned_m)], colors=[HOME_COLOUR],
                                                         radii=[0.2], labels=[f"home {key}"]))

    def _log_trail(self, key: str, point: tuple[float, float, float], colour: tuple[int, int, int]) -> None:
        trail = self._trails.setdefault(key, deque(maxlen=TRAIL_POINTS))
        if not trail or _distance(trail[-1], point) >= TRAIL_SPACING_M:
            trail.append(point)
        grown = self._trail_sent.get(key) != len(trail) or len(trail) == TRAIL_POINTS
        if self._frames % TRAIL_EVERY == 0 and grown and len(trail) > 1:
            self._trail_sent[key] = len(trail)
            self.rec.log(f"world/{key}/trail", self.rr.LineStrips3D([list(trail)], colors=[colour], radii=[0.05]))

    def _log_position_plots(self, key: str, frame: Frame, pos: tuple[float, float, float]) -> None:
        """North, east and altitude: each one entity with two series, the position and the setpoint (NaN: none)."""
        rr, rec = self.rr, self.rec
        sp = frame.setpoint_ned_m
        home_down = frame.home_ned_m[2] if frame.home_ned_m is not None else 0.0
        for axis, index in AXES:
            rec.log(f"plots/{axis}/{key}", rr.Scalars([pos[index], sp[index] if sp is not None else NAN]))
        rec.log(f"plots/altitude/{key}", rr.Scalars([home_down - pos[2], home_down - sp[2] if sp is not None
                                                     else NAN]))

    def _log_state(self, key: str, frame: Frame) -> None:
        rr, rec = self.rr, self.rec
        rec.log(f"plots/armed/{key}", rr.Scalars(1.0 if frame.armed else 0.0))
        state = (frame.mode, frame.armed)
        if self._modes.get(key) != state:
            self._modes[key] = state
            text = f"{key}: {frame.mode}, {'armed' if frame.armed else 'disarmed'}"
            rec.log(f"modes/{key}", rr.TextLog(text, level="INFO"))

    def _colour(self, key: str) -> tuple[int, int, int]:
        index = self.keys.index(key) if key in self.keys else len(self.keys)
        return PALETTE[index % len(PALETTE)]

    def _log_static(self) -> None:
        rr, rec = self.rr, self.rec
        rec.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
        for key in self.keys:
            colour = self._colour(key)
            for axis in ("north", "east", "altitude"):
                name = "altitude" if axis == "altitude" else "position"
                rec.log(f"plots/{axis}/{key}", rr.SeriesLines(colors=[colour, SETPOINT_COLOUR],
                                                              names=[f"{key} {name}", f"{key} setpoint"]),
                        static=True)
            rec.log(f"plots/armed/{key}", rr.SeriesLines(colors=[colour], names=[f"{key} armed"]), static=True)
            rec.log(f"plots/sticks/{key}", rr.SeriesLines(names=[f"{key} {name}" for name in STICKS]), static=True)

    def _show_sticks_panel(self) -> None:
        """The first sticks (a joystick, or a MANUAL_CONTROL client of the emulator): the layout again, now with
        the sticks panel, made active. Until then there is none: OFFBOARD setpoints come without sticks."""
        if not self._sticks_shown:
            self._sticks_shown = True
            self.rec.send_blueprint(self._blueprint(), make_active=True, make_default=True)

    def _blueprint(self) -> Any:
        import rerun.blueprint as rrb

        panels = [("north", "north (m)", 2.0), ("east", "east (m)", 2.0), ("altitude", "altitude above home (m)", 2.0),
                  ("sticks", "sticks (-1..1)", 2.0), ("armed", "armed", 1.5)]
        shown = [p for p in panels if p[0] != "sticks" or self._sticks_shown]
        plots = [rrb.TimeSeriesView(origin=f"plots/{axis}", name=title) for axis, title, _ in shown]
        return rrb.Blueprint(
            rrb.Horizontal(rrb.Spatial3DView(origin="world", name="3D", line_grid=rrb.archetypes.LineGrid3D(
                               visible=True, spacing=1.0), eye_controls=rrb.archetypes.EyeControls3D(
                               position=EYE_POSITION, look_target=EYE_TARGET)),
                           rrb.Vertical(*plots, rrb.TextLogView(origin="modes", name="modes"),
                                        row_shares=[share for _, _, share in shown] + [2.0]),
                           column_shares=[3, 2]),
            rrb.TimePanel(timeline="flight_time", play_state="following"),  # the live end, however slow the page
            collapse_panels=True)


def _distance(a: tuple[float, float, float], b: tuple[float, float, float]) -> float:
    return float(((a[0] - b[0]) ** 2 + (a[1] - b[1]) ** 2 + (a[2] - b[2]) ** 2) ** 0.5)
