"""A Vehicle with a stored mission, flown item by item (no MAVLink): the current item, the items reached and the
texts over simulated time, for the navigator's tests (tests/sitl_emu/navigator)."""

from __future__ import annotations

import math
from collections.abc import Callable

from sitl_emu.geo import ned_to_global
from sitl_emu.navigator.mission_store import PLAN_MISSION, MissionItem
from sitl_emu.px4 import MavCmd, MavResult, NavState
from sitl_emu.types import VehicleCommand
from sitl_emu.vehicle.vehicle import Vehicle

NAN = math.nan
WP, LOITER_UNLIM, LOITER_TIME, LAND, TAKEOFF, DELAY = 16, 17, 19, 21, 22, 93
DO_JUMP, DO_CHANGE_SPEED, ROI_LOCATION, ROI_NONE = 177, 178, 195, 197
REL, AMSL, MISSION_FRAME = 6, 5, 2


class Flight:
    """A vehicle with a stored mission; records the current item and the items reached, per time."""

    def __init__(self, items: list[tuple[int, float, float, float, tuple[float, ...], int]]) -> None:
        self.v = Vehicle()
        self.store = self.v.mission_store()
        stored = []
        for seq, (cmd, n, e, alt, params, frame) in enumerate(items):
            lat, lon, _ = ned_to_global(self.v.ref, (n, e, 0.0))
            p = (*params, 0.0, 0.0, 0.0, NAN)[:4]
            x, y = (round(lat * 1e7), round(lon * 1e7)) if frame != MISSION_FRAME else (0, 0)
            stored.append(MissionItem(seq, frame, cmd, 1, *p, x, y, alt))
        self.store.replace(PLAN_MISSION, tuple(stored))
        self.currents: list[int] = []
        self.reached: list[tuple[int, float]] = []
        self.texts: list[str] = []
        self._seen = self.v.last_event_seq

    def command(self, cmd: int, *params: float) -> int:
        ack = self.v.handle_command(VehicleCommand(cmd, (*params, *([NAN] * (7 - len(params))))))
        assert ack is not None
        return ack.result

    def start(self) -> None:
        self.v.run_for(2.5)
        assert self.command(MavCmd.COMPONENT_ARM_DISARM, 1, 0) == MavResult.ACCEPTED
        self.v.run_for(1.0)
        assert self.command(MavCmd.MISSION_START, 0, 0) == MavResult.ACCEPTED

    def run_until(self, done: Callable[[], bool], timeout_s: float = 60.0) -> float:
        """Step until done() (asserts it happens); returns the time (s)."""
        end = self.v.time_us + timeout_s * 1e6
        while self.v.time_us < end:
            self.v.step()
            self._record()
            if done():
                return self.v.time_us * 1e-6
        raise AssertionError(f"not done within {timeout_s} s: currents {self.currents}, reached {self.reached}")

    def _record(self) -> None:
        if not self.currents or self.currents[-1] != self.store.current_seq:
            self.currents.append(self.store.current_seq)
        if self.store.seq_reached >= 0 and (not self.reached or self.reached[-1][0] != self.store.seq_reached):
            self.reached.append((self.store.seq_reached, self.v.time_us * 1e-6))
        for e in self.v.events_after(self._seen):
            self.texts.append(e.text)
            self._seen = e.seq

    def at(self, n: float, e: float) -> float:
        p = self.v.snapshot().pos_ned_m
        return math.hypot(p[0] - n, p[1] - e)

    @property
    def speed(self) -> float:
        vel = self.v.snapshot().vel_ned_m_s
        return math.hypot(vel[0], vel[1])


def wp(n: float, e: float, alt: float = 5.0, *params: float, cmd: int = WP, frame: int = REL) -> tuple:
    return (cmd, n, e, alt, params, frame)


def do(cmd: int, *params: float) -> tuple:
    return (cmd, 0.0, 0.0, 0.0, params, MISSION_FRAME)


TAKEOFF_ITEM = wp(0, 0, 5.0, cmd=TAKEOFF)


def fly_until_disarmed(f: Flight) -> tuple[list[int], list[int], list[tuple[float, float, float]], list[NavState]]:
    """Fly until disarmed (at most 180 s): MISSION_CURRENT seqs from the one in force, the items reached, the path
    (local NED, every step) and the armed modes in their order."""
    currents_before, reached_before = len(f.currents), len(f.reached)
    path: list[tuple[float, float, float]] = []
    modes: list[NavState] = []

    def landed() -> bool:
        snap = f.v.snapshot()
        path.append(snap.pos_ned_m)
        if snap.armed and (not modes or modes[-1] is not snap.nav_state):
            modes.append(snap.nav_state)
        return not snap.armed

    f.run_until(landed, 180.0)
    return f.currents[currents_before - 1:], [s for s, _ in f.reached[reached_before:]], path, modes
