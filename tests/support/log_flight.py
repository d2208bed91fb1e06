"""A takeoff-and-land flight over loopback in lockstep with logging on, and the client that recorded it."""

from __future__ import annotations

import math
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sitl_emu.px4 import MavCmd, MavResult, NavState
from sitl_emu.testing.client import FlightClient
from sitl_emu.testing.sim import Sim

NAN = math.nan
TAKEOFF_ALT_M = 3.0


class RecordingClient(FlightClient):
    """A FlightClient that also keeps every message it receives, by type."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.watch_all()
        self.received: dict[str, list[Any]] = defaultdict(list)
        self._next_gcs_heartbeat_s = -math.inf

    def pump(self) -> None:
        """Also a GCS HEARTBEAT every second: the vehicle sends STATUSTEXT only to a link with a GCS."""
        super().pump()
        if self.clock.now() >= self._next_gcs_heartbeat_s:
            self.send(self.mav.heartbeat_encode(6, 8, 0, 0, 4))  # MAV_TYPE_GCS, MAV_AUTOPILOT_INVALID
            self._next_gcs_heartbeat_s = self.clock.now() + 1.0

    def _observe(self, msg: Any) -> None:
        self.received[msg.get_type()].append(msg)
        super()._observe(msg)


@dataclass
class Flight:
    sim: Sim
    client: RecordingClient
    log_dir: Path


def fly_takeoff_land(log_dir: Path, seed: int = 0, change_param: bool = True, sdlog_mode: int = 0) -> Flight:
    """Arm, take off to TAKEOFF_ALT_M, hold, (set MPC_XY_VEL_MAX in flight), land, auto-disarm; the Sim stays open.
    SDLOG_MODE 0 (a log from arming to disarming) unless `sdlog_mode` says otherwise (PX4 SITL's is 1)."""
    sim = Sim(log_dir=log_dir, seed=seed, params={"MIS_TAKEOFF_ALT": TAKEOFF_ALT_M, "SDLOG_MODE": sdlog_mode})
    c = RecordingClient(sim.ports(0).gcs, sim.clock)
    c.wait(lambda: c.healthy, 30.0, "health all good")
    assert c.command(MavCmd.COMPONENT_ARM_DISARM, 1) == MavResult.ACCEPTED
    assert c.command(MavCmd.NAV_TAKEOFF, NAN, NAN, NAN, NAN, NAN, NAN, NAN) == MavResult.ACCEPTED
    c.wait(lambda: c.armed, 5.0, "armed")
    c.wait(lambda: c.seen.pos_ned_m is not None and -c.seen.pos_ned_m[2] > TAKEOFF_ALT_M - 0.2, 30.0, "altitude")
    c.wait(lambda: c.in_mode(NavState.AUTO_LOITER), 30.0, "Hold after takeoff")
    if change_param:
        c.send(c.mav.param_set_encode(1, 1, b"MPC_XY_VEL_MAX", 7.5, 9))
    c.spin(2.0)
    assert c.command(MavCmd.NAV_LAND) == MavResult.ACCEPTED
    c.wait(lambda: not c.armed, 40.0, "landing and auto-disarm")
    c.spin(1.0)
    return Flight(sim, c, log_dir)


def log_files(log_dir: Path) -> list[Path]:
    return sorted(log_dir.glob("*/*.ulg"))
