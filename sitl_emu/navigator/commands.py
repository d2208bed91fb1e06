"""What a command asks of the navigator: the requests the commander queues (takeoff altitude, reposition, altitude
change, orbit) for the mode executor to apply when it starts or restarts a task."""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

from sitl_emu.types import NAN


class NavCommandKind(Enum):
    TAKEOFF = "takeoff"
    REPOSITION = "reposition"
    CHANGE_ALTITUDE = "change_altitude"
    ORBIT = "orbit"  # DO_ORBIT: the orbit flight task applies it (flight_tasks/orbit.py)


@dataclass(frozen=True, slots=True)
class NavCommand:
    """A request for the navigator that comes with a command (global coordinates, NaN = keep current)."""

    kind: NavCommandKind
    lat_deg: float = NAN
    lon_deg: float = NAN
    alt_amsl_m: float = NAN
    yaw_rad: float = NAN
    speed_m_s: float = NAN
    radius_m: float = NAN  # DO_ORBIT param1 (the sign is the direction); speed_m_s is its param2
    yaw_behaviour: float = NAN  # DO_ORBIT param3 (ORBIT_YAW_BEHAVIOUR)
