"""The case "Return direct with geofence obstruction" of PX4's own SITL suite (PX4-Autopilot
test/mavsdk_tests/test_multicopter_rtl_with_geofence.cpp): its plan,
test/mavsdk_tests/multicopter_mission_geofence_avoid.plan (the coordinates as that file gives them), moved to the
vehicle's position as AutopilotTesterRtl:: load_qgc_mission_and_geofence_here does, and the breach test of its
monitor (point_breaches_shape on local north/east)."""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Final

from sitl_emu.geo import GeoRef, global_to_ned
from sitl_emu.navigator.mission_store import MissionItem
from sitl_emu.px4 import MavCmd

REL_ALT_FRAME, MISSION_FRAME, GLOBAL_FRAME = 3, 2, 0
# (command, lat, lon, relative altitude) of the plan's mission; the last item is the RTL (MAV_FRAME_MISSION)
MISSION: Final = ((MavCmd.NAV_TAKEOFF, 47.3977508, 8.5456074, 20.0),
                  (MavCmd.NAV_WAYPOINT, 47.396545599479346, 8.544490781870365, 20.0),
                  (MavCmd.NAV_WAYPOINT, 47.39635128979426, 8.53915466175144, 20.0),
                  (MavCmd.NAV_WAYPOINT, 47.39446602392638, 8.540564444881795, 20.0))
EXCLUSION_POLYGON: Final = ((47.3991036, 8.5368519), (47.3985883, 8.543435299999999), (47.3967667, 8.544253699999999),
                            (47.3968827, 8.541781799999999))
INCLUSION_POLYGON: Final = ((47.39999163985872, 8.535047740378417), (47.39994510029728, 8.545445143543049),
                            (47.39274987948735, 8.551976999573185), (47.39365751759516, 8.53812458836515))
EXCLUSION_CIRCLE: Final = ((47.395306422855064, 8.54286777893347), 111.05361447891983)
RTL_AT_SEQ: Final = 3  # execute_rtl_when_reaching_mission_sequence(3)


def _e7(deg: float) -> int:
    return int(deg * 1e7)  # static_cast<int32_t>, as MAVSDK's import


@dataclass(frozen=True, slots=True)
class Plan:
    mission: tuple[MissionItem, ...]
    fence: tuple[MissionItem, ...]


def plan_here(lat_deg: float, lon_deg: float) -> Plan:
    """The mission and the fence moved so that the takeoff item is at (lat_deg, lon_deg)."""
    dx, dy = _e7(MISSION[0][1]) - _e7(lat_deg), _e7(MISSION[0][2]) - _e7(lon_deg)
    nan = math.nan
    mission = [MissionItem(seq, REL_ALT_FRAME, cmd, 1, 0.0, 0.0, 0.0, nan, _e7(lat) - dx, _e7(lon) - dy, alt)
               for seq, (cmd, lat, lon, alt) in enumerate(MISSION)]
    mission.append(MissionItem(len(mission), MISSION_FRAME, MavCmd.NAV_RETURN_TO_LAUNCH, 1, 0.0, 0.0, 0.0, 0.0, 0, 0,
                               0.0))
    fence: list[MissionItem] = []
    for command, polygon in ((MavCmd.NAV_FENCE_POLYGON_VERTEX_EXCLUSION, EXCLUSION_POLYGON),
                             (MavCmd.NAV_FENCE_POLYGON_VERTEX_INCLUSION, INCLUSION_POLYGON)):
        for lat, lon in polygon:
            fence.append(MissionItem(len(fence), GLOBAL_FRAME, command, 1, float(len(polygon)), 0.0, 0.0, 0.0,
                                     _e7(lat) - dx, _e7(lon) - dy, 0.0))
    (lat, lon), radius = EXCLUSION_CIRCLE
    fence.append(MissionItem(len(fence), GLOBAL_FRAME, MavCmd.NAV_FENCE_CIRCLE_EXCLUSION, 1, radius, 0.0, 0.0, 0.0,
                             _e7(lat) - dx, _e7(lon) - dy, 0.0))
    return Plan(tuple(mission), tuple(fence))


def _inside(north: float, east: float, polygon: list[tuple[float, float]]) -> bool:
    """point_in_polygon_local (crossing number on north/east)."""
    inside = False
    j = len(polygon) - 1
    for i in range(len(polygon)):
        ni, ei = polygon[i]
        nj, ej = polygon[j]
        if (ei > east) != (ej > east) and north < (nj - ni) * (east - ei) / (ej - ei) + ni:
            inside = not inside
        j = i
    return inside


class BreachMonitor:
    """start_monitoring_geofence_breach: the uploaded shapes in the local frame of `ref`; `check` latches a breach
    (entering an exclusion shape or leaving an inclusion one)."""

    def __init__(self, fence: Sequence[Any], ref: GeoRef) -> None:
        """`fence`: the uploaded fence items (anything with command, param1, x, y: ours or MAVSDK's)."""
        def local(item: Any) -> tuple[float, float]:
            n, e, _ = global_to_ned(ref, item.x * 1e-7, item.y * 1e-7, ref.alt_amsl_m)
            return n, e

        self.exclusion = [local(it) for it in fence if it.command == MavCmd.NAV_FENCE_POLYGON_VERTEX_EXCLUSION]
        self.inclusion = [local(it) for it in fence if it.command == MavCmd.NAV_FENCE_POLYGON_VERTEX_INCLUSION]
        circle = next(it for it in fence if it.command == MavCmd.NAV_FENCE_CIRCLE_EXCLUSION)
        self.circle_centre, self.circle_radius_m = local(circle), circle.param1
        self.breach: tuple[float, float] | None = None

    def check(self, north: float, east: float) -> None:
        in_circle = math.hypot(north - self.circle_centre[0], east - self.circle_centre[1]) < self.circle_radius_m
        breached = _inside(north, east, self.exclusion) or not _inside(north, east, self.inclusion) or in_circle
        if breached and self.breach is None:
            self.breach = (north, east)


def write_qgc_plan(path: Path) -> Path:
    """The plan as a QGroundControl .plan file (what the case hands MAVSDK's import_qgroundcontrol_mission)."""
    items: list[dict[str, Any]] = [
        {"type": "SimpleItem", "command": int(cmd), "frame": REL_ALT_FRAME, "autoContinue": True, "doJumpId": i + 1,
         "params": [0, 0, 0, None, lat, lon, alt]} for i, (cmd, lat, lon, alt) in enumerate(MISSION)]
    items.append({"type": "SimpleItem", "command": int(MavCmd.NAV_RETURN_TO_LAUNCH), "frame": MISSION_FRAME,
                  "autoContinue": True, "doJumpId": len(items) + 1, "params": [0, 0, 0, 0, 0, 0, 0]})
    (c_lat, c_lon), radius = EXCLUSION_CIRCLE
    plan = {
        "fileType": "Plan", "version": 1, "groundStation": "QGroundControl",
        "mission": {"version": 2, "firmwareType": 12, "vehicleType": 2, "cruiseSpeed": 15, "hoverSpeed": 5,
                    "globalPlanAltitudeMode": 1, "plannedHomePosition": [47.3977444, 8.5455918, 489.338],
                    "items": items},
        "geoFence": {"version": 2,
                     "polygons": [{"version": 1, "inclusion": False, "polygon": [list(v) for v in EXCLUSION_POLYGON]},
                                  {"version": 1, "inclusion": True, "polygon": [list(v) for v in INCLUSION_POLYGON]}],
                     "circles": [{"version": 1, "inclusion": False,
                                  "circle": {"center": [c_lat, c_lon], "radius": radius}}]},
        "rallyPoints": {"version": 2, "points": []},
    }
    path.write_text(json.dumps(plan, indent=1))
    return path
