"""HIL_STATE_QUATERNION, PX4 SITL's ground-truth stream (streams/HIL_STATE_QUATERNION.hpp): off on both links until a
client asks, rates by SET_MESSAGE_INTERVAL, one by REQUEST_MESSAGE, and the physics' true state, not the estimate."""

from __future__ import annotations

import math

import pytest
from support.fakes import HOME, Harness

from sitl_emu.disturbance.estimate import EstimateNoiseSettings
from sitl_emu.geo import ned_to_global
from sitl_emu.px4 import MavCmd, MavResult
from sitl_emu.vehicle.vehicle import Vehicle

HIL_STATE_QUATERNION = 115


@pytest.fixture
def h():
    harness = Harness(Vehicle(home=HOME, estimate_noise=EstimateNoiseSettings(pos_white_m=0.3), seed=5))
    yield harness
    harness.close()


def _acks(client, command):
    return [a.result for a in client.of_type("COMMAND_ACK") if a.command == command]


def test_no_link_streams_ground_truth_until_asked(h):
    h.gcs.heartbeat()
    h.run(3.0)
    assert not h.api.of_type("HIL_STATE_QUATERNION")
    assert not h.gcs.of_type("HIL_STATE_QUATERNION")


def test_set_message_interval_starts_it_at_that_rate_on_that_link_only_and_minus_one_stops_it(h):
    h.run(1.0)
    h.api.command_long(MavCmd.SET_MESSAGE_INTERVAL, HIL_STATE_QUATERNION, 1e6 / 15)  # MAVSDK set_rate_ground_truth(15)
    h.run(0.1)
    assert _acks(h.api, MavCmd.SET_MESSAGE_INTERVAL) == [MavResult.ACCEPTED]
    h.api.received.clear()
    h.run(4.0)
    assert 59 <= len(h.api.of_type("HIL_STATE_QUATERNION")) <= 61
    assert not h.gcs.of_type("HIL_STATE_QUATERNION")
    h.api.command_long(MavCmd.GET_MESSAGE_INTERVAL, HIL_STATE_QUATERNION)
    h.run(0.05)
    assert h.api.of_type("MESSAGE_INTERVAL")[-1].interval_us == 66666
    h.api.command_long(MavCmd.SET_MESSAGE_INTERVAL, HIL_STATE_QUATERNION, -1)
    h.run(0.1)
    h.api.received.clear()
    h.run(1.0)
    assert not h.api.of_type("HIL_STATE_QUATERNION")


def test_request_message_sends_one_before_the_ack(h):
    h.run(0.5)
    h.gcs.command_long(MavCmd.REQUEST_MESSAGE, HIL_STATE_QUATERNION)
    h.run(0.05)
    kinds = [m.get_type() for m in h.gcs.received if m.get_type() in ("HIL_STATE_QUATERNION", "COMMAND_ACK")]
    assert kinds == ["HIL_STATE_QUATERNION", "COMMAND_ACK"]
    assert _acks(h.gcs, MavCmd.REQUEST_MESSAGE) == [MavResult.ACCEPTED]


def test_content_is_the_true_state_not_the_noisy_estimate_in_px4_units(h):
    h.run(2.5)
    h.api.command_long(MavCmd.COMPONENT_ARM_DISARM, 1.0)
    h.run(0.1)
    h.api.command_long(MavCmd.NAV_TAKEOFF)  # to MIS_TAKEOFF_ALT
    h.api.command_long(MavCmd.SET_MESSAGE_INTERVAL, HIL_STATE_QUATERNION, 20_000)
    h.run(7.0)
    h.api.received.clear()
    h.vehicle.step()
    h.io()
    (msg,) = h.api.of_type("HIL_STATE_QUATERNION")
    truth = h.vehicle._state  # the physics this step
    lat, lon, alt = ned_to_global(h.vehicle.ref, truth.pos_ned_m)
    assert msg.time_usec == 0  # PX4's stream never sets it
    assert (msg.lat, msg.lon, msg.alt) == (int(lat * 1e7), int(lon * 1e7), int(alt * 1e3))
    assert msg.alt > (HOME[2] + 1.5) * 1e3  # in the air, AMSL
    assert list(msg.attitude_quaternion) == pytest.approx(truth.q_wxyz, abs=1e-6)
    assert (msg.rollspeed, msg.pitchspeed, msg.yawspeed) == pytest.approx(truth.rates_frd_rad_s, abs=1e-6)
    assert (msg.vx, msg.vy, msg.vz) == tuple(int(v * 100) for v in truth.vel_ned_m_s)
    assert (msg.xacc, msg.yacc, msg.zacc) == tuple(int(a) for a in truth.acc_ned_m_s2)  # m/s^2, unscaled, as PX4
    assert (msg.ind_airspeed, msg.true_airspeed) == (0, 0)
    # the estimate carries 0.3 m of position noise: the ground truth is not it
    estimate = h.vehicle.snapshot()
    assert math.dist(estimate.pos_ned_m, truth.pos_ned_m) > 0.01
