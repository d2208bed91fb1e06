"""Return's geofence avoidance planner, the cases of PX4 main's
src/modules/navigator/GeofenceAvoidancePlannerTest.cpp (the same fences, starts and destinations, margin 0), and the
fence of test/mavsdk_tests/multicopter_mission_geofence_avoid.plan with the multicopter margin."""

from __future__ import annotations

import math

from sitl_emu.geo import GeoRef, global_to_ned
from sitl_emu.navigator.geofence_avoidance import GeofenceAvoidancePlanner, LocalArea, dijkstra_backward
from sitl_emu.navigator.planner_polygons import AddResult, PlannerPolygons

EXCLUSION = ((47.3552420, 8.5192293), (47.3555843, 8.5201174), (47.3551382, 8.5209143), (47.3550828, 8.5171901))
L_INCLUSION = ((47.3562241, 8.5186720), (47.3562479, 8.5195691), (47.3550948, 8.5196762), (47.3549660, 8.5171633),
               (47.3555168, 8.5171278), (47.3554507, 8.5187742))
REF = GeoRef(47.3559, 8.5190, 0.0)


def _xy(lat_lon: tuple[float, float]) -> tuple[float, float]:
    x, y, _ = global_to_ned(REF, lat_lon[0], lat_lon[1], 0.0)
    return x, y


def _plan(vertices: tuple[tuple[float, float], ...], inclusion: bool, start: tuple[float, float],
          destination: tuple[float, float]) -> list[tuple[float, float]]:
    areas = [LocalArea(inclusion, tuple(_xy(v) for v in vertices))] if vertices else []
    planner = GeofenceAvoidancePlanner(areas, 0.0)
    planner.set_destination(_xy(destination))
    return planner.path_from(_xy(start))


def _near(a: tuple[float, float], b: tuple[float, float]) -> bool:
    return math.dist(a, b) < 0.01


def test_no_fence_flies_direct() -> None:
    assert _plan((), False, (47.3977, 8.5456), (47.3977, 8.5456)) == []  # StartEqualsDestination
    assert _plan((), False, (47.3977, 8.5456), (47.3984, 8.5470)) == []  # DirectPathNoFence


def test_path_around_an_exclusion_zone_via_its_vertices_1_and_2() -> None:
    path = _plan(EXCLUSION, False, (47.3559582, 8.5192064), (47.3546153, 8.5193195))
    assert len(path) == 2 and _near(path[0], _xy(EXCLUSION[1])) and _near(path[1], _xy(EXCLUSION[2]))


def test_path_inside_an_l_shaped_inclusion_zone_via_its_inner_corner() -> None:
    path = _plan(L_INCLUSION, True, (47.3560041, 8.5191872), (47.3553241, 8.5177686))
    assert len(path) == 1 and _near(path[0], _xy(L_INCLUSION[5]))


def test_no_path_when_destination_or_start_breaks_the_fence() -> None:
    assert _plan(L_INCLUSION, True, (47.3560041, 8.5191872), (47.3540, 8.5150)) == []  # destination outside
    assert _plan(EXCLUSION, False, (47.3559582, 8.5192064), (47.3551506, 8.5193859)) == []  # destination inside
    assert _plan(EXCLUSION, False, (47.3551506, 8.5193859), (47.3559582, 8.5192064)) == []  # start inside


def test_a_start_inside_the_fence_falls_back_on_the_last_routable_start() -> None:
    anchor, destination, inside = (47.3559582, 8.5192064), (47.3560100, 8.5192300), (47.3553000, 8.5197000)
    planner = GeofenceAvoidancePlanner([LocalArea(False, tuple(_xy(v) for v in EXCLUSION))], 0.0)
    planner.set_destination(_xy(destination))
    assert planner.path_from(_xy(anchor)) == []  # direct from there; latched
    path = planner.path_from(_xy(inside))
    assert len(path) == 1 and _near(path[0], _xy(anchor))


def test_nan_start_or_destination_and_refused_polygons_fly_direct() -> None:
    assert _plan(EXCLUSION, False, (math.nan, 8.5192064), (47.3546153, 8.5193195)) == []
    assert _plan(EXCLUSION, False, (47.3559582, 8.5192064), (47.3546153, math.nan)) == []
    duplicate = (*L_INCLUSION, L_INCLUSION[-1])  # DuplicateNeighborVertex: a zero-length edge
    assert _plan(duplicate, True, (47.3560041, 8.5191872), (47.3553241, 8.5177686)) == []
    bowtie = ((0.0, 0.0), (10.0, 10.0), (10.0, 0.0), (0.0, 10.0))
    assert PlannerPolygons().add_polygon(bowtie, False, 0.0) is AddResult.DEGENERATE


def test_circles_become_8_gons_outside_an_exclusion_and_inside_an_inclusion() -> None:
    poly = PlannerPolygons()
    assert poly.add_circle((0.0, 0.0), 100.0, 20.0, False) is AddResult.SUCCESS
    assert poly.add_circle((0.0, 0.0), 300.0, 20.0, True) is AddResult.SUCCESS
    out = [math.hypot(*poly.node(i)) for i in range(1, 9)]
    inner = [math.hypot(*poly.node(i)) for i in range(9, 17)]
    assert all(abs(r - (100.0 / math.cos(math.pi / 8) + 20.0)) < 0.01 for r in out)
    assert all(abs(r - 280.0) < 0.01 for r in inner)
    assert poly.add_circle((0.0, 0.0), 0.05, 0.0, False) is AddResult.DEGENERATE


def test_dijkstra_gives_the_shortest_way_and_the_next_node() -> None:
    inf = math.inf
    costs = [[inf, 1.0, 5.0], [1.0, inf, 1.0], [5.0, 1.0, inf]]
    best, following = dijkstra_backward(costs, 0)
    assert best == [0.0, 1.0, 2.0] and following[2] == 1 and following[1] == 0


def test_a_sharp_corner_is_cut_off_by_two_nodes_the_margin_away() -> None:
    poly = PlannerPolygons()
    spike = ((0.0, 0.0), (100.0, 10.0), (0.0, 20.0))  # exclusion with a 11 degree corner at (100, 10)
    assert poly.add_polygon(spike, False, 5.0) is AddResult.SUCCESS
    assert poly.num_nodes == 1 + 4
    tip = [poly.node(i) for i in range(1, 5) if poly.node(i)[0] > 100.0]
    assert len(tip) == 2 and all(abs(x - 105.0) < 0.02 for x, _ in tip)
