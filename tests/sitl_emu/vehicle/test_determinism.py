"""Same seed, parameters and inputs -> bit-identical snapshots and events; a different noise seed differs."""

from __future__ import annotations

import pytest
from support.flights import scripted_flight as _script

from sitl_emu.vehicle.vehicle import Vehicle

pytestmark = pytest.mark.slow  # processes or long flights: not in `make test-fast`


def test_same_inputs_give_identical_runs() -> None:
    assert _script(Vehicle(seed=7)) == _script(Vehicle(seed=7))


def test_noise_is_seeded() -> None:
    a = _script(Vehicle(seed=1, position_noise_m=0.05))
    b = _script(Vehicle(seed=1, position_noise_m=0.05))
    c = _script(Vehicle(seed=2, position_noise_m=0.05))
    assert a == b
    assert a != c
