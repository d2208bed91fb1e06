"""Return's geofence avoidance planner as PX4's navigator drives it (navigator_main.cpp, rtl.cpp): the warnings when
the graph cannot be built or the destination breaks the fence, and the start latched once a second that a Return
from outside the fence flies back to first (GeofenceAvoidancePlannerTest.cpp
FallsBackToSavedAnchorWhenStartViolatesFence, on a Vehicle)."""

from __future__ import annotations

import math

from sitl_emu.geo import GeoRef, ned_to_global
from sitl_emu.navigator.geofence import FenceArea, Vertex
from sitl_emu.navigator.mission_store import PLAN_FENCE, MissionItem
from sitl_emu.params import default_registry
from sitl_emu.px4 import MavCmd, MavResult, NavState, Severity
from sitl_emu.types import VehicleCommand
from sitl_emu.vehicle.rtl_avoidance import RtlAvoidance
from sitl_emu.vehicle.vehicle import Vehicle

REF = GeoRef(47.397742, 8.545594, 489.4)
SQUARE = ((20.0, -20.0), (60.0, -20.0), (60.0, 20.0), (20.0, 20.0))  # north of home, an exclusion


def _area(points: tuple[tuple[float, float], ...]) -> FenceArea:
    vertices = tuple(Vertex(*ned_to_global(REF, (n, e, 0.0))[:2], True) for n, e in points)
    return FenceArea(MavCmd.NAV_FENCE_POLYGON_VERTEX_EXCLUSION, vertices)


class _Texts:
    def __init__(self) -> None:
        self.said: list[tuple[Severity, str]] = []

    def __call__(self, severity: Severity, module: str, text: str, is_event: bool, statustext: bool) -> None:
        self.said.append((severity, text))


def test_a_degenerate_fence_and_a_destination_inside_it_are_told_once() -> None:
    avoidance, texts = RtlAvoidance(default_registry()), _Texts()
    bowtie = (_area(((20.0, -20.0), (60.0, 20.0), (60.0, -20.0), (20.0, 20.0))),)
    for _ in range(2):
        assert avoidance.path(bowtie, (80.0, 0.0, -10.0), (0.0, 0.0, 0.0), REF, texts) == []
    assert texts.said == [(Severity.WARNING, "Geofence data invalid (code 7), RTL will fly directly")]
    texts.said.clear()
    square = (_area(SQUARE),)
    for _ in range(2):
        assert avoidance.path(square, (80.0, 0.0, -10.0), (40.0, 0.0, 0.0), REF, texts) == []
    assert texts.said == [(Severity.WARNING, "RTL destination breaches geofence, will fly directly")]


def test_a_start_inside_the_fence_falls_back_on_the_start_latched_a_second_before() -> None:
    avoidance, texts = RtlAvoidance(default_registry()), _Texts()
    square = (_area(SQUARE),)
    avoidance.track(0, square, (80.0, 5.0, -10.0), lambda: (0.0, 0.0, 0.0), REF, texts)
    path = avoidance.path(square, (40.0, 0.0, -10.0), (0.0, 0.0, 0.0), REF, texts)
    assert path[0] == (80.0, 5.0) and len(path) == 3  # the latched start, then around two corners (margin 20 m)
    assert all(abs(e) > 20.0 for _, e in path[1:]) and texts.said == []


def _command(v: Vehicle, cmd: int, *params: float) -> int:
    ack = v.handle_command(VehicleCommand(cmd, (*params, *([math.nan] * (7 - len(params))))))
    assert ack is not None
    return ack.result


def test_return_from_inside_an_exclusion_flies_back_out_where_it_entered() -> None:
    v = Vehicle()
    v.params.set("GF_ACTION", 1)  # warn only: the vehicle may enter the area
    stored = [MissionItem(i, 0, MavCmd.NAV_FENCE_POLYGON_VERTEX_EXCLUSION, 1, 4.0, 0.0, 0.0, 0.0,
                          round(lat * 1e7), round(lon * 1e7), 0.0)
              for i, (lat, lon, _) in enumerate(ned_to_global(v.ref, (n, e, 0.0)) for n, e in SQUARE)]
    v.mission_store().replace(PLAN_FENCE, tuple(stored))
    v.run_for(3.0)
    assert _command(v, MavCmd.COMPONENT_ARM_DISARM, 1, 0) == MavResult.ACCEPTED
    assert _command(v, MavCmd.NAV_TAKEOFF) == MavResult.ACCEPTED
    v.run_for(12.0)
    lat, lon, alt = ned_to_global(v.ref, (40.0, -45.0, -2.5))  # west of the square, then into it from the west
    assert _command(v, MavCmd.DO_REPOSITION, -1, 1, 0, math.nan, lat, lon, alt) == MavResult.ACCEPTED
    v.run_for(20.0)
    lat, lon, _ = ned_to_global(v.ref, (40.0, 0.0, -2.5))
    assert _command(v, MavCmd.DO_REPOSITION, -1, 1, 0, math.nan, lat, lon, alt) == MavResult.ACCEPTED
    v.run_for(15.0)
    seen = v.last_event_seq
    assert _command(v, MavCmd.NAV_RETURN_TO_LAUNCH) == MavResult.ACCEPTED
    v.run_for(0.1)
    assert v.snapshot().nav_state is NavState.AUTO_RTL
    west_of_square = False
    for _ in range(40 * 250):
        v.step()
        _, e, _ = v.ground_truth().pos_ned_m
        west_of_square = west_of_square or e < -20.0
        if not v.snapshot().armed:
            break
    texts = [e.text for e in v.events_after(seen)]
    assert "RTL: avoiding geofence" in texts and west_of_square  # back out the way it came, not straight home
