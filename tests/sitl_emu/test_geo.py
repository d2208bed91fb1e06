from __future__ import annotations

import math

import pytest

from sitl_emu.geo import GeoRef, global_to_ned, ned_to_global

HOME = GeoRef(47.397742, 8.545594, 488.0)


@pytest.mark.parametrize("ned", [(0.0, 0.0, 0.0), (10.0, 0.0, -2.5), (-350.0, 1200.0, -60.0), (5000.0, -7000.0, 3.0)])
def test_round_trip_returns_the_same_local_position(ned):
    lat, lon, alt = ned_to_global(HOME, ned)
    back = global_to_ned(HOME, lat, lon, alt)
    assert back == pytest.approx(ned, abs=1e-6)


def test_origin_is_the_reference():
    assert ned_to_global(HOME, (0.0, 0.0, 0.0)) == pytest.approx((47.397742, 8.545594, 488.0))


def test_north_and_east_move_latitude_and_longitude_by_the_expected_amount():
    lat, lon, alt = ned_to_global(HOME, (111.19, 0.0, -10.0))
    assert lat - HOME.lat_deg == pytest.approx(0.001, rel=1e-3)
    assert lon == pytest.approx(HOME.lon_deg, abs=1e-9)
    assert alt == pytest.approx(498.0)
    lat, lon, _ = ned_to_global(HOME, (0.0, 100.0, 0.0))
    expected_dlon = math.degrees(100.0 / (6371000.0 * math.cos(math.radians(HOME.lat_deg))))
    assert lon - HOME.lon_deg == pytest.approx(expected_dlon, rel=1e-4)
