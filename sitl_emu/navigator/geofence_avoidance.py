"""Return's way around the geofence: the shortest path from the vehicle to the return destination that keeps out of
every exclusion area and inside every inclusion area, with a margin. Pure: a function of the fence areas (local
frame), the start, the destination and the margin.

Written from PX4 main's src/modules/navigator/geofence_avoidance_planner.cpp (updateGraphFromGeofence,
updateDestination, planPath, findBestStartingNode, updateStartAndFillPath) over lib/geofence (planner_polygons.py)
and lib/dijkstra (solveBackward), and navigator_main.cpp (geofence_avoidance_margin: 2 x NAV_ACC_RAD for a
multicopter):
- a visibility graph over the areas' nodes (the destination is node 0), costs the legs' lengths, solved from the
  destination (Dijkstra);
- from the start: no path (flown direct) when the destination is in sight, when there is no fence, when an area is
  refused (degenerate, too many nodes), when no node is in sight; else the nodes from the best node in sight (leg
  length + its distance to the destination) to the destination, the destination itself not included;
- a start that breaks the fence falls back on the last start that could route (latched by an earlier plan), which
  is then flown to first.
PX4 plans around a reference at the first vertex of the first area; here the vehicle's local frame (the same
azimuthal projection, centimetre-level differences at fence distances).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from sitl_emu.geo import GeoRef, global_to_ned
from sitl_emu.navigator.geofence import FenceArea
from sitl_emu.navigator.planner_polygons import (
    CIRCLE_VERTICES,
    MAX_NODES,
    XY,
    AddResult,
    PlannerPolygons,
    max_vertices_after_splitting,
)


@dataclass(frozen=True, slots=True)
class LocalArea:
    """One fence area in the local frame: a polygon's vertices, or a circle's centre (vertices[0]) and radius."""

    inclusion: bool
    vertices: tuple[XY, ...]
    radius_m: float = math.nan
    circle: bool = False


def local_areas(areas: Sequence[FenceArea], ref: GeoRef) -> list[LocalArea]:
    """The fence's areas (navigator/geofence.py) in the local frame, as the planner reads them."""
    out = []
    for area in areas:
        xy = tuple(global_to_ned(ref, v.lat_deg, v.lon_deg, ref.alt_amsl_m)[:2] for v in area.vertices)
        if area.circle:
            out.append(LocalArea(area.inclusion, xy[:1], area.radius_m, circle=True))
        else:
            out.append(LocalArea(area.inclusion, xy))
    return out


def dijkstra_backward(costs: Sequence[Sequence[float]], destination: int) -> tuple[list[float], list[int]]:
    """Each node's shortest distance to `destination` and its next node on the way (-1: none)."""
    n = len(costs)
    best = [math.inf] * n
    following = [-1] * n
    visited = [False] * n
    best[destination] = 0.0
    for _ in range(n):
        node, node_cost = -1, math.inf
        for i in range(n):
            if not visited[i] and best[i] < node_cost:
                node, node_cost = i, best[i]
        if node < 0:
            break
        visited[node] = True
        for j in range(n):
            cost = node_cost + costs[node][j]
            if not visited[j] and cost < best[j]:
                best[j], following[j] = cost, node
    return best, following


# GeofenceAvoidancePlanner::Status, the codes navigator_main.cpp reports ("Geofence data invalid (code %d)")
STATUS_OK, STATUS_NO_FENCE, STATUS_DESTINATION_BREACHES = 0, 1, 4
_ADD_STATUS = {AddResult.BUDGET_EXCEEDED: 5, AddResult.OUT_OF_RANGE: 6, AddResult.DEGENERATE: 7}


class GeofenceAvoidancePlanner:
    """The graph of one fence and margin, solved for one destination; `path_from` plans from a start. `status`:
    why the graph could not be built (a STATUS_* or a refused area's code), else STATUS_OK."""

    def __init__(self, areas: Sequence[LocalArea], margin_m: float) -> None:
        self.polygons, self.status = self._build(areas, margin_m)
        self._best: list[float] = []
        self._following: list[int] = []
        self._saved_start: XY | None = None
        self._destination: XY | None = None

    @staticmethod
    def _build(areas: Sequence[LocalArea], margin_m: float) -> tuple[PlannerPolygons | None, int]:
        """updateGraphFromGeofence: no graph when there is no fence, it has too many nodes or an area is refused."""
        needed = sum(CIRCLE_VERTICES if a.circle else max_vertices_after_splitting(len(a.vertices)) for a in areas)
        if needed == 0:
            return None, STATUS_NO_FENCE
        if needed > MAX_NODES - 1:
            return None, _ADD_STATUS[AddResult.BUDGET_EXCEEDED]
        polygons = PlannerPolygons()
        for area in areas:
            if area.circle:
                result = polygons.add_circle(area.vertices[0], area.radius_m, margin_m, area.inclusion)
            else:
                result = polygons.add_polygon(area.vertices, area.inclusion, margin_m)
            if result is not AddResult.SUCCESS:
                return None, _ADD_STATUS[result]
        return polygons, STATUS_OK

    def set_destination(self, destination: XY) -> bool:
        """updateDestination: the costs and the solution for a new destination; True when it is new and inside a
        forbidden area (PlannerPolygons::setDestination: kept, but the planner's status says it breaches)."""
        polygons = self.polygons
        if polygons is None or not all(math.isfinite(c) for c in destination):
            self._destination = None
            return False
        if self._destination is not None and math.dist(destination, polygons.node(0)) < 0.1:
            return False
        polygons.set_destination(destination)
        self._destination = destination
        n = polygons.num_nodes
        costs = [[math.inf] * n for _ in range(n)]
        for i in range(n):
            for j in range(i + 1, n):
                costs[i][j] = costs[j][i] = polygons.edge_cost(i, j)
        self._best, self._following = dijkstra_backward(costs, 0)
        return polygons.crosses_any(polygons.x_cm[0], polygons.y_cm[0], polygons.x_cm[0], polygons.y_cm[0])

    def _best_node(self, start: XY) -> tuple[int, bool]:
        """findBestStartingNode: the node in sight with the shortest way on, and whether the destination is in sight."""
        polygons = self.polygons
        assert polygons is not None
        direct, best_index, best_cost = False, -1, math.inf
        for index in range(polygons.num_nodes):
            if not polygons.visible_from(start, index):
                continue
            if index == 0:
                direct = True
                continue
            cost = math.dist(start, polygons.node(index)) + self._best[index]
            if cost < best_cost:
                best_index, best_cost = index, cost
        return best_index, direct

    def path_from(self, start: XY) -> list[XY]:
        """updateStartAndFillPath: the waypoints to fly before the destination (empty: fly direct)."""
        polygons = self.polygons
        if polygons is None or self._destination is None or not all(math.isfinite(c) for c in start):
            return []
        best, direct = self._best_node(start)
        feasible = best >= 0 or direct
        if feasible:
            self._saved_start = start
        path: list[XY] = []
        if not feasible and self._saved_start is not None:
            best, direct = self._best_node(self._saved_start)
            if best >= 0 or direct:
                path.append(self._saved_start)
        if not direct and best >= 0:
            node = best
            for _ in range(polygons.num_nodes):
                path.append(polygons.node(node))
                node = self._following[node]
                if node <= 0:
                    break
        return path
