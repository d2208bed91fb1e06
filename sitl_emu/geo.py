"""Local NED <-> geodetic conversion around a reference point.

Azimuthal equidistant projection on a sphere, as PX4's MapProjection (src/lib/geo/geo.cpp, map_projection_project /
reproject) with CONSTANTS_RADIUS_OF_EARTH = 6371000 m. Altitude: alt_amsl = ref_alt - down.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Final

from sitl_emu.control.qmath import acos, asin, atan2, degrees, hypot, radians
from sitl_emu.types import Vec3

EARTH_RADIUS_M: Final = 6371000.0  # PX4 lib/geo/geo.h CONSTANTS_RADIUS_OF_EARTH
# Where PX4's SIH starts (lat_deg, lon_deg, alt_amsl_m): the defaults of SIH_LOC_LAT0 / SIH_LOC_LON0 / SIH_LOC_H0
# (src/modules/simulation/simulator_sih/sih_params.yaml; ../shared/reference/px4-params.json reads 489.4 m), the
# emulator's default home
SIH_HOME: Final[tuple[float, float, float]] = (47.397742, 8.545594, 489.4)


@dataclass(frozen=True, slots=True)
class GeoRef:
    """The local frame's origin: NED (0, 0, 0) is here."""

    lat_deg: float
    lon_deg: float
    alt_amsl_m: float
    # derived once (ned_to_global runs for every telemetry snapshot): the reference in radians, its sine and cosine
    lat_rad: float = field(init=False, repr=False, compare=False)
    lon_rad: float = field(init=False, repr=False, compare=False)
    sin_lat: float = field(init=False, repr=False, compare=False)
    cos_lat: float = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        lat_rad = math.radians(self.lat_deg)
        object.__setattr__(self, "lat_rad", lat_rad)
        object.__setattr__(self, "lon_rad", math.radians(self.lon_deg))
        object.__setattr__(self, "sin_lat", math.sin(lat_rad))
        object.__setattr__(self, "cos_lat", math.cos(lat_rad))


def _unit_clamped(x: float) -> float:
    """x limited to -1..1 for asin/acos (rounding can take a cosine past 1); NaN stays NaN."""
    return -1.0 if x < -1.0 else (1.0 if x > 1.0 else x)


def ned_to_global(ref: GeoRef, pos_ned_m: Vec3) -> tuple[float, float, float]:
    """(lat_deg, lon_deg, alt_amsl_m) of a local NED position."""
    x_rad = pos_ned_m[0] / EARTH_RADIUS_M
    y_rad = pos_ned_m[1] / EARTH_RADIUS_M
    c = hypot(x_rad, y_rad)
    if c > 0.0:
        sin_c, cos_c = math.sin(c), math.cos(c)
        sin_ref, cos_ref = ref.sin_lat, ref.cos_lat
        lat = asin(_unit_clamped(cos_c * sin_ref + x_rad * sin_c * cos_ref / c))
        lon = ref.lon_rad + atan2(y_rad * sin_c, c * cos_ref * cos_c - x_rad * sin_ref * sin_c)
    else:
        lat, lon = ref.lat_rad, ref.lon_rad
    lon_deg = (degrees(lon) + 180.0) % 360.0 - 180.0
    return degrees(lat), lon_deg, ref.alt_amsl_m - pos_ned_m[2]


def global_to_ned(ref: GeoRef, lat_deg: float, lon_deg: float, alt_amsl_m: float) -> Vec3:
    """Local NED position (m) of a geodetic point."""
    lat = radians(lat_deg)
    d_lon = radians(lon_deg - ref.lon_deg)
    sin_ref, cos_ref = ref.sin_lat, ref.cos_lat
    sin_lat, cos_lat = math.sin(lat), math.cos(lat)
    cos_d_lon = math.cos(d_lon)
    c = acos(_unit_clamped(sin_ref * sin_lat + cos_ref * cos_lat * cos_d_lon))
    k = 1.0 if abs(c) < 1e-12 else c / math.sin(c)
    north = k * (cos_ref * sin_lat - sin_ref * cos_lat * cos_d_lon) * EARTH_RADIUS_M
    east = k * cos_lat * math.sin(d_lon) * EARTH_RADIUS_M
    return north, east, ref.alt_amsl_m - alt_amsl_m
