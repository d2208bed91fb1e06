"""The fence as Return's geofence avoidance planner sees it: polygons and circles moved away from their forbidden side
by a margin, held as integer centimetres, and the test whether a straight leg between two points stays legal. Pure.

Written from PX4 main's src/lib/geofence/geofence_utils.h/.cpp (PlannerPolygons, orient2d, collinearBetween,
segmentsIntersect, maxVerticesAfterSplitting):
- a polygon is stored so that its forbidden side is on the left of each edge (counter-clockwise for an exclusion,
  clockwise for an inclusion); each vertex moves `margin` away from it along the corner's bisector (scaled to keep the
  edges parallel); a convex corner sharper than 60 degrees is cut off by two nodes `margin` from the vertex;
  self-intersecting polygons, fewer than 3 vertices, zero-length or folded-back edges are refused;
- a circle is a regular 8-gon: around the circle grown by the margin (exclusion), inside it shrunk by the margin
  (inclusion);
- node 0 is the destination; nodes at a corner whose forbidden side spans 180 degrees or more cannot lie on a
  shortest path and are never used;
- a leg is legal when it crosses no forbidden interior: running along a boundary or touching a corner is allowed;
  only legs tangent at both ends (bitangent) join two nodes.
Coordinates are local (x north, y east, metres) in, centimetres (rounded half away from zero) inside; the orientation
tests are exact on integers.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from enum import Enum
from typing import Final

MAX_NODES: Final = 100  # CONFIG_NAVIGATOR_GEOFENCE_MAX_NODES
MAX_POLYGONS: Final = 16
CIRCLE_VERTICES: Final = 8
_EPS: Final = 1.1920929e-07  # FLT_EPSILON
_RANGE_M: Final = (1 << 30) / 100.0  # inFixedPointRange

XY = tuple[float, float]


class AddResult(Enum):
    SUCCESS = 0
    BUDGET_EXCEEDED = 1
    OUT_OF_RANGE = 2
    DEGENERATE = 3


class SegSeg(Enum):
    DISJOINT = 0
    CROSS = 1
    A_INSIDE_CD = 2
    B_INSIDE_CD = 3
    C_INSIDE_AB = 4
    D_INSIDE_AB = 5
    COLLINEAR = 6


def to_cm(m: float) -> int:
    """roundf(m * 100): half away from zero."""
    return int(math.copysign(math.floor(abs(m) * 100.0 + 0.5), m))


def orient2d(ax: int, ay: int, bx: int, by: int, cx: int, cy: int) -> int:
    """+1 if c is left of a->b, -1 if right, 0 if collinear."""
    det = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    return (det > 0) - (det < 0)


def collinear_between(ax: int, ay: int, bx: int, by: int, cx: int, cy: int) -> bool:
    """For collinear a, b, c: is c on the open segment ab?"""
    if abs(ax - bx) >= abs(ay - by):
        return ax < cx < bx or bx < cx < ax
    return ay < cy < by or by < cy < ay


def segments_intersect(ax: int, ay: int, bx: int, by: int, cx: int, cy: int, dx: int, dy: int) -> SegSeg:
    """segmentsIntersect: how segment ab meets segment cd."""
    o1, o2 = orient2d(ax, ay, bx, by, cx, cy), orient2d(ax, ay, bx, by, dx, dy)
    if o1 != 0 and o1 == o2:
        return SegSeg.DISJOINT
    o3, o4 = orient2d(cx, cy, dx, dy, ax, ay), orient2d(cx, cy, dx, dy, bx, by)
    if o3 != 0 and o3 == o4:
        return SegSeg.DISJOINT
    if o1 and o2 and o3 and o4 and o1 != o2 and o3 != o4:
        return SegSeg.CROSS
    if not (o1 or o2 or o3 or o4):
        return SegSeg.COLLINEAR
    if o3 == 0 and collinear_between(cx, cy, dx, dy, ax, ay):
        return SegSeg.A_INSIDE_CD
    if o4 == 0 and collinear_between(cx, cy, dx, dy, bx, by):
        return SegSeg.B_INSIDE_CD
    if o1 == 0 and collinear_between(ax, ay, bx, by, cx, cy):
        return SegSeg.C_INSIDE_AB
    if o2 == 0 and collinear_between(ax, ay, bx, by, dx, dy):
        return SegSeg.D_INSIDE_AB
    return SegSeg.DISJOINT


def polygon_ccw(vertices: Sequence[XY]) -> bool:
    """isPolygonCCW (shoelace): False for clockwise or zero area."""
    n = len(vertices)
    area2 = sum(vertices[i][0] * vertices[(i + 1) % n][1] - vertices[(i + 1) % n][0] * vertices[i][1]
                for i in range(n))
    return area2 > 0.0


def max_vertices_after_splitting(n: int) -> int:
    """maxVerticesAfterSplitting: the most nodes a simple polygon of n vertices can become."""
    return 0 if n < 3 else n + (180 * n + 360 - 1) // 300


def _self_intersecting(vertices: Sequence[XY]) -> bool:
    n = len(vertices)
    cm = [(to_cm(x), to_cm(y)) for x, y in vertices]
    for i in range(n):
        a, b = cm[i], cm[(i + 1) % n]
        for j in range(i + 2, n):
            if i == 0 and j == n - 1:
                continue  # adjacent edges
            c, d = cm[j], cm[(j + 1) % n]
            if segments_intersect(*a, *b, *c, *d) is not SegSeg.DISJOINT:
                return True
    return False


def _unit(vx: float, vy: float) -> tuple[float, float, float]:
    norm = math.hypot(vx, vy)
    return (vx / norm, vy / norm, norm) if norm >= _EPS else (0.0, 0.0, 0.0)


@dataclass(frozen=True, slots=True)
class _Polygon:
    start: int
    count: int
    inclusion: bool
    box: tuple[int, int, int, int]  # min x, max x, min y, max y (cm)


class PlannerPolygons:
    """The planner's nodes (node 0: the destination) and the polygons they belong to."""

    def __init__(self) -> None:
        self.x_cm: list[int] = [0]
        self.y_cm: list[int] = [0]
        self.not_on_optimal_path: list[bool] = [False]
        self.polygons: list[_Polygon] = []

    @property
    def num_nodes(self) -> int:
        return len(self.x_cm)

    def node(self, index: int) -> XY:
        return self.x_cm[index] / 100.0, self.y_cm[index] / 100.0

    def set_destination(self, p: XY) -> None:
        self.x_cm[0], self.y_cm[0] = to_cm(p[0]), to_cm(p[1])

    def add_polygon(self, vertices: Sequence[XY], inclusion: bool, margin_m: float) -> AddResult:
        """addPolygon: canonical orientation, each vertex offset by the margin, sharp convex corners split."""
        n = len(vertices)
        if len(self.polygons) >= MAX_POLYGONS or self.num_nodes + n > MAX_NODES:
            return AddResult.BUDGET_EXCEEDED
        if margin_m < -_EPS or n < 3 or _self_intersecting(vertices):
            return AddResult.DEGENERATE
        if any(abs(x) >= _RANGE_M or abs(y) >= _RANGE_M for x, y in vertices):
            return AddResult.OUT_OF_RANGE
        ordered = list(reversed(vertices)) if polygon_ccw(vertices) == inclusion else list(vertices)
        nodes: list[XY] = []
        for i in range(n):
            corner = _offset_corner(ordered[i - 1], ordered[i], ordered[(i + 1) % n], margin_m,
                                    self.num_nodes + len(nodes) + 1 < MAX_NODES)
            if corner is None:
                return AddResult.DEGENERATE
            nodes.extend(corner)
        self._append(nodes, inclusion, None)
        return AddResult.SUCCESS

    def add_circle(self, centre: XY, radius_m: float, margin_m: float, inclusion: bool) -> AddResult:
        """addApproxCircle: a regular 8-gon around (exclusion) or inside (inclusion) the circle, margin applied."""
        if len(self.polygons) >= MAX_POLYGONS or self.num_nodes + CIRCLE_VERTICES > MAX_NODES:
            return AddResult.BUDGET_EXCEEDED
        if not radius_m > 0.1:
            return AddResult.DEGENERATE
        k_radius = radius_m - margin_m if inclusion else radius_m / math.cos(math.pi / CIRCLE_VERTICES) + margin_m
        if k_radius <= _EPS:
            return AddResult.DEGENERATE
        if abs(centre[0]) + k_radius >= _RANGE_M or abs(centre[1]) + k_radius >= _RANGE_M:
            return AddResult.OUT_OF_RANGE
        step = (-1.0 if inclusion else 1.0) * 2.0 * math.pi / CIRCLE_VERTICES
        nodes = [(centre[0] + k_radius * math.cos((i + 0.5) * step), centre[1] + k_radius * math.sin((i + 0.5) * step))
                 for i in range(CIRCLE_VERTICES)]
        self._append(nodes, inclusion, inclusion)
        return AddResult.SUCCESS

    def _append(self, nodes: list[XY], inclusion: bool, not_optimal: bool | None) -> None:
        start = self.num_nodes
        self.x_cm.extend(to_cm(x) for x, _ in nodes)
        self.y_cm.extend(to_cm(y) for _, y in nodes)
        xs, ys = self.x_cm[start:], self.y_cm[start:]
        count = len(nodes)
        self.polygons.append(_Polygon(start, count, inclusion, (min(xs), max(xs), min(ys), max(ys))))
        for i in range(count):
            if not_optimal is not None:
                self.not_on_optimal_path.append(not_optimal)
                continue
            p, c, nx = start + (i - 1) % count, start + i, start + (i + 1) % count
            turn = orient2d(self.x_cm[p], self.y_cm[p], self.x_cm[c], self.y_cm[c], self.x_cm[nx], self.y_cm[nx])
            self.not_on_optimal_path.append(turn <= 0)  # curves right or straight: forbidden side >= 180 degrees

    # ---- legality of a leg ----------------------------------------------------------------------------------------
    def _inside_cone(self, poly: _Polygon, px: int, py: int, v: int) -> bool:
        """pointInsideInteriorCone: does the leg from vertex v to p enter the forbidden side at v?"""
        xs, ys = self.x_cm, self.y_cm
        p, c, n = poly.start + (v - 1) % poly.count, poly.start + v, poly.start + (v + 1) % poly.count
        left_in = orient2d(xs[p], ys[p], xs[c], ys[c], px, py)
        left_out = orient2d(xs[c], ys[c], xs[n], ys[n], px, py)
        if orient2d(xs[p], ys[p], xs[c], ys[c], xs[n], ys[n]) > 0:
            return left_in > 0 and left_out > 0
        return left_in > 0 or left_out > 0

    def _crosses_inside_of(self, poly: _Polygon, sx: int, sy: int, ex: int, ey: int) -> bool:
        """intersectsInsideOf: a proper crossing, a pass through a corner into the inside, or a midpoint inside."""
        winding, mid_on_boundary = 0, False
        mx2, my2 = sx + ex, sy + ey
        xs, ys = self.x_cm, self.y_cm
        for i in range(poly.count):
            a, b = poly.start + (i - 1) % poly.count, poly.start + i
            ax, ay, bx, by = xs[a], ys[a], xs[b], ys[b]
            meet = segments_intersect(ax, ay, bx, by, sx, sy, ex, ey)
            if meet is SegSeg.CROSS:
                return True
            through_corner = meet is SegSeg.B_INSIDE_CD  # corner b on the leg: does the leg enter the inside there?
            if through_corner and (self._inside_cone(poly, sx, sy, i) or self._inside_cone(poly, ex, ey, i)):
                return True
            side = orient2d(2 * ax, 2 * ay, 2 * bx, 2 * by, mx2, my2)
            if side == 0:
                if collinear_between(2 * ax, 2 * ay, 2 * bx, 2 * by, mx2, my2) or (2 * bx == mx2 and 2 * by == my2):
                    mid_on_boundary = True
            elif 2 * ay <= my2:
                winding += 1 if (2 * by > my2 and side > 0) else 0
            elif 2 * by <= my2 and side < 0:
                winding -= 1
        if mid_on_boundary:
            return False
        return (winding != 0) != poly.inclusion

    def crosses_any(self, sx: int, sy: int, ex: int, ey: int) -> bool:
        """intersectsAnyInside (a leg wholly outside an inclusion's bounding box is outside it)."""
        lo_x, hi_x, lo_y, hi_y = min(sx, ex), max(sx, ex), min(sy, ey), max(sy, ey)
        for poly in self.polygons:
            min_x, max_x, min_y, max_y = poly.box
            if hi_x < min_x or lo_x > max_x or hi_y < min_y or lo_y > max_y:
                if poly.inclusion:
                    return True
                continue
            if self._crosses_inside_of(poly, sx, sy, ex, ey):
                return True
        return False

    def _bitangent(self, a: int, bx: int, by: int) -> bool:
        """edgeBitangent: neither the leg a->b nor its mirror about a enters the forbidden side at node a."""
        if a == 0:
            return True
        for poly in self.polygons:
            if poly.start <= a < poly.start + poly.count:
                cx, cy = 2 * self.x_cm[a] - bx, 2 * self.y_cm[a] - by
                v = a - poly.start
                return not self._inside_cone(poly, bx, by, v) and not self._inside_cone(poly, cx, cy, v)
        return True

    def edge_visible(self, a: int, b: int) -> bool:
        """edgeVisible(a, b) between two nodes."""
        if a == b or self.not_on_optimal_path[a] or self.not_on_optimal_path[b]:
            return False
        xs, ys = self.x_cm, self.y_cm
        if not self._bitangent(a, xs[b], ys[b]) or not self._bitangent(b, xs[a], ys[a]):
            return False
        return not self.crosses_any(xs[a], ys[a], xs[b], ys[b])

    def visible_from(self, p: XY, b: int) -> bool:
        """edgeVisible(point, node b)."""
        if self.not_on_optimal_path[b]:
            return False
        px, py = to_cm(p[0]), to_cm(p[1])
        if not self._bitangent(b, px, py):
            return False
        return not self.crosses_any(px, py, self.x_cm[b], self.y_cm[b])

    def edge_cost(self, a: int, b: int) -> float:
        """edgeCost: the leg's length, infinite when it is not legal."""
        if not self.edge_visible(a, b):
            return math.inf
        (ax, ay), (bx, by) = self.node(a), self.node(b)
        return math.hypot(ax - bx, ay - by)


def _offset_corner(prev: XY, vertex: XY, nxt: XY, margin_m: float, room_to_split: bool) -> list[XY] | None:
    """One corner of addPolygon, its forbidden side on the left: the node(s) `margin_m` away from it, None if the
    corner is degenerate (a zero-length edge, edges folding back)."""
    ix, iy, in_len = _unit(vertex[0] - prev[0], vertex[1] - prev[1])
    ox, oy, out_len = _unit(nxt[0] - vertex[0], nxt[1] - vertex[1])
    if in_len < _EPS or out_len < _EPS:
        return None
    bx, by = -iy + -oy, ix + ox  # the sum of the two edges' left normals
    b_len = math.hypot(bx, by)
    if b_len < _EPS:
        return None
    ux, uy = bx / b_len, by / b_len
    convex = ix * oy - iy * ox > 0.0
    if convex and b_len < 1.0 and margin_m > _EPS and room_to_split:  # interior angle below 60 degrees: cut it off
        base_x, base_y = vertex[0] - ux * margin_m, vertex[1] - uy * margin_m
        px, py = -uy, ux
        s = margin_m * (1.0 - (-oy * ux + ox * uy)) / (ox * ux + oy * uy)
        return [(base_x + px * s, base_y + py * s), (base_x - px * s, base_y - py * s)]
    scale = margin_m * 2.0 / b_len
    return [(vertex[0] - ux * scale, vertex[1] - uy * scale)]
