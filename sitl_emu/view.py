"""`sitl-emu serve --view`: every vehicle's snapshot drawn live in the browser (the flightview package, Rerun).

The runner calls the hook after each wake-up (runner.hooks, between batches of ticks, never inside the physics
tick); the hook logs at most flightview.live.RATE_HZ frames a wall second, one per vehicle, read from each
vehicle's snapshot() (cached per tick, the same one telemetry reads) and its manual-control sticks.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from flightview.launch import ViewHandle
from flightview.scene import Frame
from sitl_emu.geo import GeoRef, global_to_ned
from sitl_emu.px4 import mode_name
from sitl_emu.types import VehicleSnapshot
from sitl_emu.vehicle.vehicle import Vehicle


def vehicle_key(sysid: int) -> str:
    return f"sysid{sysid}"


def snapshot_frame(snap: VehicleSnapshot, sticks: tuple[float, float, float, float] | None,
                   origin: GeoRef | None = None) -> Frame:
    """What the view shows of one vehicle, from its snapshot; positions in the local frame of `origin` (the first
    vehicle's: each vehicle of a --count has its own local frame, with its own home as origin), else its own."""
    offset = (0.0, 0.0, 0.0)
    if origin is not None:
        offset = global_to_ned(origin, snap.ref_lat_deg, snap.ref_lon_deg, snap.ref_alt_amsl_m)
    sp = snap.local_setpoint
    setpoint = None
    if sp is not None and not any(math.isnan(c) for c in sp.position_ned_m):
        setpoint = _shift(sp.position_ned_m, offset)
    home = _shift(snap.home.pos_ned_m, offset) if snap.home is not None else None
    return Frame(time_s=snap.time_us / 1e6, pos_ned_m=_shift(snap.pos_ned_m, offset), q_wxyz=snap.q_wxyz,
                 setpoint_ned_m=setpoint, home_ned_m=home, mode=mode_name(snap.nav_state), armed=snap.armed,
                 sticks=sticks)


def _shift(v: tuple[float, float, float], by: tuple[float, float, float]) -> tuple[float, float, float]:
    return (v[0] + by[0], v[1] + by[1], v[2] + by[2])


def manual_sticks(vehicle: Vehicle, snap: VehicleSnapshot) -> tuple[float, float, float, float] | None:
    """PX4's manual_control_setpoint as forward, right, up, yaw (-1..1) while a MAVLink joystick is present."""
    if not snap.manual_control:
        return None
    m = vehicle.commander.manual.setpoint
    return (m.pitch, m.roll, m.throttle, m.yaw)


class ServeView:
    """The runner hook feeding the view from the nodes' vehicles."""

    def __init__(self, handle: ViewHandle, vehicles: Sequence[Vehicle]) -> None:
        self.handle = handle
        self.vehicles = list(vehicles)

    @staticmethod
    def keys(vehicles: Sequence[Vehicle]) -> list[str]:
        return [vehicle_key(vehicle.sysid) for vehicle in vehicles]

    def __call__(self) -> None:
        live = self.handle.live
        if not live.due():
            return
        origin = None
        for vehicle in self.vehicles:
            snap = vehicle.snapshot()
            if origin is None and len(self.vehicles) > 1:
                origin = GeoRef(snap.ref_lat_deg, snap.ref_lon_deg, snap.ref_alt_amsl_m)
            live.log(vehicle_key(vehicle.sysid), snapshot_frame(snap, manual_sticks(vehicle, snap), origin))
        live.end_frame()
