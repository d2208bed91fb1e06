"""FlightTaskManualAltitude's altitude lock, case by case (PX4 _updateAltitudeLock, MPC_ALT_MODE 0), and the manual
tasks' start from the previous task's setpoint (FlightTaskManualAltitude(SmoothVel)/ManualAcceleration::activate)."""

from __future__ import annotations

import math

import pytest

from sitl_emu.flight_tasks.manual import ManualAltitudeTask, ManualPositionTask, altitude_lock
from sitl_emu.navigator.setpoint import NavInput
from sitl_emu.params import default_registry
from sitl_emu.types import ManualControlSetpoint, TrajectorySetpoint

NAN = math.nan


@pytest.mark.parametrize(("locked", "centred", "stopped", "expected"), [
    (NAN, True, True, -12.0),  # throttle centred and slower than MPC_HOLD_MAX_Z: lock where the vehicle is
    (NAN, True, False, NAN),  # still climbing or sinking fast: not yet
    (-10.0, True, False, -10.0),  # a lock holds while the throttle stays centred, whatever the climb rate
    (-10.0, True, True, -10.0),
    (-10.0, False, True, NAN),  # any throttle frees it
    (NAN, False, True, NAN),
])
def test_altitude_lock_table(locked: float, centred: bool, stopped: bool, expected: float) -> None:
    got = altitude_lock(locked, centred, stopped, -12.0)
    assert (math.isnan(got) and math.isnan(expected)) or got == expected


def _nav(z_m: float, vz_m_s: float, vel_xy: tuple[float, float] = (0.0, 0.0)) -> NavInput:
    return NavInput(0, (0.0, 0.0, z_m), (vel_xy[0], vel_xy[1], vz_m_s), 0.0, (0.0, 0.0, 0.0), 0.0, landed=False,
                    armed=True)


def test_altitude_mode_entered_while_climbing_holds_the_altitude_it_was_entered_at() -> None:
    """activate(): the altitude setpoint is where the vehicle is; the climb-rate smoothing goes on from the previous
    task's climb rate and brakes (jerk-limited), so the first setpoints still climb, towards the locked altitude."""
    last = TrajectorySetpoint((0.0, 0.0, -19.0), (0.0, 0.0, -2.9), (0.0, 0.0, 0.0))
    task = ManualAltitudeTask(_nav(-20.0, -2.8), default_registry(), last)
    task.sticks = ManualControlSetpoint(throttle=0.0)
    sp = task.update(_nav(-20.05, -2.8), 0.02)
    assert sp.position_ned_m[2] == -20.0
    assert sp.velocity_ned_m_s[2] == pytest.approx(-2.9, abs=0.05)
    for _ in range(100):
        sp = task.update(_nav(-20.5, -0.3), 0.02)
    assert sp.position_ned_m[2] == -20.0
    assert sp.velocity_ned_m_s[2] == pytest.approx(0.0, abs=1e-6)


def test_position_mode_starts_from_the_previous_setpoints_velocity() -> None:
    """ManualAcceleration::activate: the horizontal velocity setpoint continues the last setpoint's (a Return flying
    home at 5 m/s), not the vehicle's, and brakes from there with the sticks centred."""
    last = TrajectorySetpoint((NAN, NAN, -30.0), (5.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    task = ManualPositionTask(_nav(-30.0, 0.0, (4.2, 0.0)), default_registry(), last)
    task.sticks = ManualControlSetpoint(throttle=0.0)
    sp = task.update(_nav(-30.0, 0.0, (4.2, 0.0)), 0.02)
    assert sp.velocity_ned_m_s[0] == pytest.approx(5.0, abs=0.1)
    assert math.isnan(sp.position_ned_m[0])  # moving: no horizontal lock yet
