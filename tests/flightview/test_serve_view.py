"""serve's frames: from each vehicle's snapshot; a --count's vehicles drawn side by side in the first one's frame."""

from __future__ import annotations

from typing import Any

import pytest

from sitl_emu.cli.main import build_params, build_vehicle
from sitl_emu.geo import GeoRef
from sitl_emu.runtime.swarm import DEFAULT_HOME, instance_home
from sitl_emu.view import manual_sticks, snapshot_frame


def vehicle(index: int) -> Any:
    v = build_vehicle(build_params(None, ()), instance_home(DEFAULT_HOME, index), 0, index + 1)
    for _ in range(10):
        v.step()
    return v


def test_a_second_vehicle_is_drawn_three_metres_east_of_the_first() -> None:
    first, second = vehicle(0), vehicle(1)
    origin = GeoRef(*DEFAULT_HOME)
    own = snapshot_frame(second.snapshot(), None)
    shared = snapshot_frame(second.snapshot(), None, origin)
    assert own.pos_ned_m is not None and shared.pos_ned_m is not None
    assert shared.pos_ned_m[1] - own.pos_ned_m[1] == pytest.approx(3.0, abs=0.01)
    assert shared.pos_ned_m[0] == pytest.approx(own.pos_ned_m[0], abs=0.01)
    base = snapshot_frame(first.snapshot(), None, origin)
    assert base.pos_ned_m == pytest.approx(snapshot_frame(first.snapshot(), None).pos_ned_m)


def test_a_frame_has_the_mode_and_no_sticks_without_a_joystick() -> None:
    v = vehicle(0)
    snap = v.snapshot()
    frame = snapshot_frame(snap, manual_sticks(v, snap))
    assert frame.sticks is None
    assert (frame.mode, frame.armed) == ("AUTO.LOITER", False)
    assert frame.q_wxyz == snap.q_wxyz
    assert frame.time_s == pytest.approx(snap.time_us / 1e6)
