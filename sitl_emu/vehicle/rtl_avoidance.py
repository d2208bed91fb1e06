"""Return's geofence avoidance planner as PX4's navigator drives it (navigator/geofence_avoidance.py is the planner).

After PX4 main's src/modules/navigator/navigator_main.cpp (the graph built again when the fence or the margin
changes, the margin 2 x NAV_ACC_RAD for a multicopter, "Geofence data invalid (code %d), RTL will fly directly" when
it cannot be built, "RTL destination breaches geofence, will fly directly") and rtl.cpp (setRtlTypeAndDestination,
once a second while Return is not flying: the destination set and the plan made from the vehicle's position, which
latches the last start that could route; RtlDirect::on_activation plans again from where Return begins).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Final

from sitl_emu.geo import GeoRef
from sitl_emu.navigator.geofence import FenceArea
from sitl_emu.navigator.geofence_avoidance import STATUS_NO_FENCE, STATUS_OK, GeofenceAvoidancePlanner, local_areas
from sitl_emu.params import ParamRegistry
from sitl_emu.px4 import Severity
from sitl_emu.types import Vec3

Emit = Callable[[Severity, str, str, bool, bool], None]
TRACK_PERIOD_US: Final = 1_000_000  # RTL::on_inactive: setRtlTypeAndDestination at 1 Hz


class RtlAvoidance:
    """The planner of the fence in force, kept between Returns (the latched start lives in it)."""

    def __init__(self, params: ParamRegistry) -> None:
        self.params = params
        self._planner: GeofenceAvoidancePlanner | None = None
        self._inputs: tuple[object, float] = (None, 0.0)  # the areas and margin the planner was built from
        self._next_track_us = 0

    def _graph(self, areas: Sequence[FenceArea], ref: GeoRef, emit: Emit) -> GeofenceAvoidancePlanner:
        margin_m = 2.0 * float(self.params["NAV_ACC_RAD"])
        planner = self._planner
        if planner is None or self._inputs[0] is not areas or self._inputs[1] != margin_m:
            planner = self._planner = GeofenceAvoidancePlanner(local_areas(areas, ref), margin_m)
            self._inputs = (areas, margin_m)
            if planner.status not in (STATUS_OK, STATUS_NO_FENCE):
                emit(Severity.WARNING, "navigator",
                     f"Geofence data invalid (code {planner.status}), RTL will fly directly", True, True)
        return planner

    def path(self, areas: Sequence[FenceArea], pos_ned_m: Vec3, destination_ned_m: Vec3, ref: GeoRef,
             emit: Emit) -> list[tuple[float, float]]:
        """The avoidance waypoints (north, east) from `pos_ned_m` to the destination; empty: fly there directly."""
        planner = self._graph(areas, ref, emit)
        if planner.set_destination((destination_ned_m[0], destination_ned_m[1])):
            emit(Severity.WARNING, "navigator", "RTL destination breaches geofence, will fly directly", True, True)
        return planner.path_from((pos_ned_m[0], pos_ned_m[1]))

    def track(self, now_us: int, areas: Sequence[FenceArea], pos_ned_m: Vec3, destination: Callable[[], Vec3],
              ref: GeoRef, emit: Emit) -> None:
        """Once a second while Return is not flying: plan from here (a routable position is latched as the start
        a later Return from outside the fence falls back on)."""
        if now_us < self._next_track_us:
            return
        self._next_track_us = now_us + TRACK_PERIOD_US
        if areas:
            self.path(areas, pos_ned_m, destination(), ref, emit)
