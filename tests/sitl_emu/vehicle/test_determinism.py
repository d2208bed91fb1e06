"""Same seed, parameters and inputs -> bit-identical snapshots and events; a different noise seed differs."""

from __future__ import annotations

import pytest
from support.flights import scripted_flight as _script

from sitl_emu.disturbance.estimate import EstimateNoiseSettings
from sitl_emu.vehicle.vehicle import Vehicle

pytestmark = pytest.mark.slow  # processes or long flights: not in `make test-fast`


def test_same_inputs_give_identical_runs() -> None:
    assert _script(Vehicle(seed=7)) == _script(Vehicle(seed=7))


def test_noise_is_seeded() -> None:
    noise = EstimateNoiseSettings(pos_white_m=0.05)
    a = _script(Vehicle(seed=1, estimate_noise=noise))
    b = _script(Vehicle(seed=1, estimate_noise=noise))
    c = _script(Vehicle(seed=2, estimate_noise=noise))
    assert a == b
    assert a != c
