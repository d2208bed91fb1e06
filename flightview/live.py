"""The live view: frames of vehicles logged to Rerun (the loopback viewer, a .rrd file, or both) at most RATE_HZ.

Layout: the 3D world on the left (ground grid, fence box, each vehicle's body, trail, setpoint and home), plots on
the right (north, east and altitude against the setpoint, the sticks, armed), and the mode changes as a log. One
frame costs about 1 ms of CPU in the Rerun SDK, so callers log from their own loop, never from a physics tick, and
`due()` keeps them at RATE_HZ of wall time whatever the simulation's speed.
"""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from flightview.scene import FenceBox, Frame, body_arms, fence_box, ground_grid, ned_to_enu
from flightview.server import ViewerServer, import_rerun

RATE_HZ = 25.0
TRAIL_POINTS = 1500  # one minute at RATE_HZ
TRAIL_EVERY = 5  # the trail (the longest thing logged) is sent every 5th frame: 5 Hz
AXES = (("north", 0), ("east", 1))
STICKS = ("forward", "right", "up", "yaw")
PALETTE = [(255, 160, 0), (0, 170, 255), (120, 220, 80), (230, 80, 200), (255, 90, 90), (180, 180, 255)]
SETPOINT_COLOUR = (150, 150, 150)
HOME_COLOUR = (80, 255, 120)
FENCE_COLOUR = (255, 60, 60)


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
        self.rec.set_sinks(*sinks, default_blueprint=self._blueprint())
        self._next_wall_s = 0.0
        self._trails: dict[str, deque[tuple[float, float, float]]] = {k: deque(maxlen=TRAIL_POINTS) for k in keys}
        self._modes: dict[str, tuple[str, bool]] = {}
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
                                                    fill_mode="majorwireframe", labels=["fence"]), static=True)

    def log(self, key: str, frame: Frame) -> None:
        """One vehicle's frame at its time."""
        rr, rec = self.rr, self.rec
        rec.set_time("flight_time", duration=frame.time_s)
        self._log_state(key, frame)
        if frame.pos_ned_m is not None:
            self._log_world(key, frame, frame.pos_ned_m)
            self._log_position_plots(key, frame, frame.pos_ned_m)
        if frame.sticks is not None:
            for name, value in zip(STICKS, frame.sticks, strict=True):
                rec.log(f"plots/sticks/{key}/{name}", rr.Scalars(value))

    def end_frame(self) -> None:
        self._frames += 1

    def close(self) -> None:
        self.rec.flush()
        self.rec.disconnect()

    def _log_world(self, key: str, frame: Frame, pos: tuple[float, float, float]) -> None:
        rr, rec = self.rr, self.rec
        colour = self._colour(key)
        arms = body_arms(pos, frame.q_wxyz)
        colours = [(255, 40, 40), (255, 40, 40), colour, colour, (230, 230, 230)]  # red: the front arms
        rec.log(f"world/{key}/body", rr.LineStrips3D(arms, colors=colours, radii=[0.06]))
        trail = self._trails.setdefault(key, deque(maxlen=TRAIL_POINTS))
        trail.append(ned_to_enu(pos))
        if self._frames % TRAIL_EVERY == 0 and len(trail) > 1:
            rec.log(f"world/{key}/trail", rr.LineStrips3D([list(trail)], colors=[colour], radii=[0.03]))
        if frame.setpoint_ned_m is not None:
            rec.log(f"world/{key}/setpoint", rr.Points3D([ned_to_enu(frame.setpoint_ned_m)],
                                                         colors=[SETPOINT_COLOUR], radii=[0.15]))
        if frame.home_ned_m is not None:
            rec.log(f"world/{key}/home", rr.Points3D([ned_to_enu(frame.home_ned_m)], colors=[HOME_COLOUR],
                                                     radii=[0.2], labels=[f"home {key}"]))

    def _log_position_plots(self, key: str, frame: Frame, pos: tuple[float, float, float]) -> None:
        rr, rec = self.rr, self.rec
        sp = frame.setpoint_ned_m
        home_down = frame.home_ned_m[2] if frame.home_ned_m is not None else 0.0
        for axis, index in AXES:
            rec.log(f"plots/{axis}/{key}/position", rr.Scalars(pos[index]))
            if sp is not None:
                rec.log(f"plots/{axis}/{key}/setpoint", rr.Scalars(sp[index]))
        rec.log(f"plots/altitude/{key}/altitude", rr.Scalars(home_down - pos[2]))
        if sp is not None:
            rec.log(f"plots/altitude/{key}/setpoint", rr.Scalars(home_down - sp[2]))

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
        rec.log("world/grid", rr.LineStrips3D(ground_grid(), colors=[(90, 90, 90)], radii=[0.01]), static=True)
        for key in self.keys:
            colour = self._colour(key)
            for axis in ("north", "east", "altitude"):
                name = "altitude" if axis == "altitude" else "position"
                rec.log(f"plots/{axis}/{key}/{name}", rr.SeriesLines(colors=[colour], names=[f"{key} {name}"]),
                        static=True)
                rec.log(f"plots/{axis}/{key}/setpoint", rr.SeriesLines(colors=[SETPOINT_COLOUR],
                                                                        names=[f"{key} setpoint"]), static=True)
            rec.log(f"plots/armed/{key}", rr.SeriesLines(colors=[colour], names=[f"{key} armed"]), static=True)
            for name in STICKS:
                rec.log(f"plots/sticks/{key}/{name}", rr.SeriesLines(names=[f"{key} {name}"]), static=True)

    def _blueprint(self) -> Any:
        import rerun.blueprint as rrb

        plots = [rrb.TimeSeriesView(origin=f"plots/{axis}", name=title) for axis, title in (
            ("north", "north (m)"), ("east", "east (m)"), ("altitude", "altitude above home (m)"),
            ("sticks", "sticks (-1..1)"), ("armed", "armed"))]
        return rrb.Blueprint(
            rrb.Horizontal(rrb.Spatial3DView(origin="world", name="3D"),
                           rrb.Vertical(*plots, rrb.TextLogView(origin="modes", name="modes")),
                           column_shares=[3, 2]),
            collapse_panels=True)
