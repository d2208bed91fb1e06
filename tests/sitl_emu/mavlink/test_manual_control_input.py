"""MANUAL_CONTROL as input: PX4's scaling, garbage, the wrong target, COM_RC_IN_MODE, and a 1 kHz flood.

PX4 (mavlink_receiver.cpp handle_message_manual_control): pitch x/1000, roll y/1000, yaw r/1000, throttle z/500 - 1;
a field outside its range counts as 0 (so a bad z is the throttle centred, never full); target 0 or our sysid.
"""

from __future__ import annotations

import math

import pytest
from support.fakes import Client, Harness

from sitl_emu.mavlink.receiver import manual_setpoint
from sitl_emu.params import default_registry
from sitl_emu.px4 import MavCmd, NavState
from sitl_emu.vehicle.vehicle import Vehicle

INT16_MIN, INT16_MAX = -32768, 32767


def test_scaling_as_px4_reads_it():
    sp = manual_setpoint(1000, -500, 750, -1000, 5)
    assert (sp.pitch, sp.roll, sp.throttle, sp.yaw, sp.buttons) == (1.0, -0.5, 0.5, -1.0, 5)
    assert manual_setpoint(0, 0, 500, 0, 0).throttle == 0.0  # 500 is the centre
    assert manual_setpoint(0, 0, 0, 0, 0).throttle == -1.0


@pytest.mark.parametrize("x, y, z, r", [(INT16_MAX, INT16_MIN, INT16_MAX, INT16_MIN), (1001, -1001, 1001, 1001),
                                        (0, 0, -1, 0), (INT16_MIN, INT16_MAX, INT16_MIN, INT16_MAX)])
def test_out_of_range_fields_count_as_centred(x, y, z, r):
    sp = manual_setpoint(x, y, z, r, 0)
    assert sp.pitch == 0.0 or abs(x) <= 1000
    assert sp.roll == 0.0 or abs(y) <= 1000
    assert sp.yaw == 0.0 or abs(r) <= 1000
    assert sp.throttle == 0.0 or 0 <= z <= 1000
    assert all(-1.0 <= v <= 1.0 and math.isfinite(v) for v in (sp.pitch, sp.roll, sp.yaw, sp.throttle))


def _vehicle_in_position_mode(params=None) -> tuple[Harness, Client]:
    h = Harness(Vehicle(params=params))
    c = h.api
    h.run(2.5)
    c.heartbeat()
    c.command_long(MavCmd.DO_SET_MODE, 1, 3, 0)
    h.run(0.2)
    return h, c


def _stream(h: Harness, c: Client, seconds: float, target: int = 1, per_tick: int = 1,
            fields: tuple[int, int, int, int] = (0, 0, 500, 0)) -> None:
    def send() -> None:
        for _ in range(per_tick):
            c.send(c.mav.manual_control_encode(target, *fields, 0))
    h.run(seconds, send)


def _system_status(c: Client) -> int:
    return c.of_type("HEARTBEAT")[-1].system_status


@pytest.mark.slow
def test_a_stream_for_another_system_is_ignored():
    h, c = _vehicle_in_position_mode()
    try:
        _stream(h, c, 1.5, target=7)
        assert _system_status(c) == 0  # Position mode still has no manual control: not ready to arm
        _stream(h, c, 1.5, target=0)  # target 0 is everyone
        assert _system_status(c) == 3
    finally:
        h.close()


@pytest.mark.parametrize("mode", [0, 4])
def test_com_rc_in_mode_without_mavlink_ignores_the_stream(mode):
    params = default_registry()
    params.set("COM_RC_IN_MODE", mode)
    h, c = _vehicle_in_position_mode(params)
    try:
        _stream(h, c, 1.5)
        assert _system_status(c) == 0
        assert h.vehicle.commander.nav_state is NavState.POSCTL
    finally:
        h.close()


def test_a_1khz_flood_of_garbage_flies_nothing_beyond_the_sticks():
    h, c = _vehicle_in_position_mode()
    try:
        _stream(h, c, 1.0)
        c.command_long(MavCmd.COMPONENT_ARM_DISARM, 1)
        _stream(h, c, 1.0)
        assert h.vehicle.snapshot().armed
        # 1 kHz (4 per 4 ms tick) of int16 extremes: every field out of range counts as centred, so the vehicle
        # stays on the ground, armed and idle, and keeps answering
        _stream(h, c, 3.0, per_tick=4, fields=(INT16_MAX, INT16_MIN, INT16_MAX, INT16_MIN))
        snap = h.vehicle.snapshot()
        assert snap.armed and snap.pos_ned_m[2] == pytest.approx(0.0, abs=0.01)
        assert h.node.api.stats.handler_errors == 0
        assert _system_status(c) == 4
    finally:
        h.close()
