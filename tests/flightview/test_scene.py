"""The view's geometry: NED to the view's east-north-up world, the arms turned by the attitude, the fence box."""

from __future__ import annotations

import math

import pytest

from flightview.scene import FenceBox, body_arms, euler_to_q, fence_box, ned_to_enu, rotate


def close(a: tuple[float, ...], b: tuple[float, ...]) -> bool:
    return all(math.isclose(x, y, abs_tol=1e-9) for x, y in zip(a, b, strict=True))


def test_ned_is_drawn_east_north_up() -> None:
    assert ned_to_enu((1.0, 2.0, -3.0)) == (2.0, 1.0, 3.0)


def test_yaw_east_turns_the_nose_east() -> None:
    q = euler_to_q(0.0, 0.0, math.pi / 2)
    assert close(rotate(q, (1.0, 0.0, 0.0)), (0.0, 1.0, 0.0))  # forward points east in NED


def test_roll_right_lowers_the_right_arm() -> None:
    q = euler_to_q(math.radians(30), 0.0, 0.0)
    down = rotate(q, (0.0, 1.0, 0.0))[2]
    assert down == pytest.approx(math.sin(math.radians(30)))


def test_the_front_arms_of_a_level_quad_facing_north_point_north_in_the_view() -> None:
    arms = body_arms((0.0, 0.0, -2.0), euler_to_q(0.0, 0.0, 0.0))
    assert len(arms) == 5
    for strip in arms[:2]:
        assert strip[0] == (0.0, 0.0, 2.0)  # from the centre, 2 m up
        assert strip[1][1] > 0  # y is north in the view
        assert strip[1][2] == pytest.approx(2.0)  # level
    assert arms[4][1][2] > 2.0  # the mast points up


def test_fence_box_spans_the_altitude_band_around_home() -> None:
    centre, half = fence_box(FenceBox((1.0, 2.0, 0.0), 5.0, 0.5, 10.0))
    assert centre == (2.0, 1.0, 5.25)
    assert half == (5.0, 5.0, 4.75)
