"""The receiver turns wire messages into the inputs PX4's mavlink_receiver.cpp would publish (reference 3, 4)."""

from __future__ import annotations

import math

import pytest
from support.fakes import Client, FakeVehicle, Harness

from sitl_emu.px4 import MavCmd, MavResult, NavState, Severity

NAN = math.nan


@pytest.fixture
def h():
    harness = Harness(FakeVehicle())
    yield harness
    harness.close()


def _acks(client: Client) -> list[tuple[int, int]]:
    return [(a.command, a.result) for a in client.of_type("COMMAND_ACK")]


def _local_ned(client: Client, mask: int, frame: int = 1, pos=(0.0, 0.0, 0.0), vel=(0.0, 0.0, 0.0),
               acc=(0.0, 0.0, 0.0), yaw=0.0, yaw_rate=0.0, target=(1, 1)) -> None:
    client.send(client.mav.set_position_target_local_ned_encode(0, target[0], target[1], frame, mask, *pos, *vel,
                                                                *acc, yaw, yaw_rate))


# --- commands: routing (3.1) ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("target, answered", [
    ((1, 1), True), ((1, 0), True), ((0, 0), False), ((0, 1), False), ((2, 1), False), ((1, 2), False),
])
def test_command_long_is_ours_only_for_exactly_our_sysid(h, target, answered):
    """evaluate_target_ok(): target_system must be ours (0 is not enough), target_component ours or 0."""
    h.api.command_long(MavCmd.COMPONENT_ARM_DISARM, 1.0, target=target)
    h.io()
    assert bool(h.vehicle.commands) is answered
    assert _acks(h.api) == ([(MavCmd.COMPONENT_ARM_DISARM, MavResult.ACCEPTED)] if answered else [])


@pytest.mark.parametrize("target", [(0, 0), (1, 0), (1, 5), (0, 99)])
def test_legacy_capability_requests_accept_broadcast_and_any_component(h, target):
    h.api.command_long(MavCmd.REQUEST_AUTOPILOT_CAPABILITIES, 1.0, target=target)
    h.io()
    assert _acks(h.api) == [(MavCmd.REQUEST_AUTOPILOT_CAPABILITIES, MavResult.ACCEPTED)]
    assert h.api.of_type("AUTOPILOT_VERSION")


def test_command_params_source_and_external_flag_reach_the_vehicle(h):
    h.api.command_long(MavCmd.NAV_TAKEOFF, NAN, 0.0, 0.0, 1.5, 47.1, 8.2, 500.0)
    h.io()
    (cmd,) = h.vehicle.commands
    assert cmd.command == MavCmd.NAV_TAKEOFF and cmd.from_external
    assert (cmd.source_system, cmd.source_component) == (255, 190)
    assert math.isnan(cmd.param(1)) and cmd.param(4) == 1.5 and cmd.param(7) == pytest.approx(500.0)


def test_command_long_with_int32_max_lat_lon_is_denied_before_the_vehicle(h):
    h.api.command_long(MavCmd.DO_REPOSITION, -1.0, 1.0, 0.0, NAN, 2147483647.0, 2147483647.0, 500.0)
    h.io()
    assert not h.vehicle.commands
    assert _acks(h.api) == [(MavCmd.DO_REPOSITION, MavResult.DENIED)]


def test_no_ack_when_the_vehicle_says_none(h):
    h.vehicle.acks[MavCmd.COMPONENT_ARM_DISARM] = None  # ARM_DISARM with param1 not 0/1: PX4 sends no ACK
    h.api.command_long(MavCmd.COMPONENT_ARM_DISARM, 2.0)
    h.io()
    assert h.vehicle.commands and not _acks(h.api)


def test_vehicle_ack_goes_to_every_link_that_has_heard_the_sender(h):
    h.gcs.heartbeat()  # same sysid/compid (255/190) heard on the GCS link too
    h.io()
    h.api.command_long(MavCmd.COMPONENT_ARM_DISARM, 1.0)
    h.io()
    assert _acks(h.api) == [(MavCmd.COMPONENT_ARM_DISARM, 0)] and _acks(h.gcs) == [(MavCmd.COMPONENT_ARM_DISARM, 0)]
    ack = h.api.of_type("COMMAND_ACK")[0]
    assert (ack.target_system, ack.target_component) == (255, 190)


def _command_int(client: Client, command: int, frame: int, x: int, y: int, z: float = 10.0) -> None:
    client.send(client.mav.command_int_encode(1, 1, frame, command, 0, 0, 1.0, 2.0, 3.0, 4.0, x, y, z))


def test_command_int_x_y_are_degrees_e7_and_int32_max_means_unset(h):
    _command_int(h.api, MavCmd.DO_REPOSITION, 5, 473977420, 85455940)  # GLOBAL_INT: degrees * 1e7
    _command_int(h.api, MavCmd.DO_REPOSITION, 1, 123456, -50000)  # a local frame: PX4 <= v1.17 still divides by 1e7
    _command_int(h.api, MavCmd.DO_REPOSITION, 5, 2147483647, 2147483647)  # INT32_MAX: "not set" -> NaN
    h.io()
    c = h.vehicle.commands
    assert (c[0].param(5), c[0].param(6), c[0].param(7)) == pytest.approx((47.397742, 8.545594, 10.0))
    assert (c[1].param(5), c[1].param(6)) == pytest.approx((0.0123456, -0.005))
    assert math.isnan(c[2].param(5)) and math.isnan(c[2].param(6))
    assert c[0].params[:4] == (1.0, 2.0, 3.0, 4.0)


def test_command_int_with_nan_pattern_xy_is_denied(h):
    _command_int(h.api, MavCmd.DO_REPOSITION, 5, 0x7FF80000, 0x7FF80000)
    h.io()
    assert not h.vehicle.commands and _acks(h.api) == [(MavCmd.DO_REPOSITION, MavResult.DENIED)]


# PX4 main's mavlink_command_params.hpp: a value in a param the command does not take is DENIED at the boundary
@pytest.mark.parametrize("command, params", [
    (MavCmd.NAV_RETURN_TO_LAUNCH, (1.0,)),  # takes no param at all
    (MavCmd.DO_SET_MODE, (1.0, 4.0, 3.0, 5.0)),  # params 4-7
    (MavCmd.COMPONENT_ARM_DISARM, (1.0, 0.0, 7.0)),  # params 3-7
    (MavCmd.NAV_TAKEOFF, (NAN, 3.0)),  # params 2 and 3 on a multicopter
    (MavCmd.COMPONENT_ARM_DISARM, (1.0, 0.0, 0.0, 0.0, 0.0, 0.0, -2.5)),
])
def test_command_long_with_a_value_in_an_unused_param_is_denied_before_the_vehicle(h, command, params):
    h.api.command_long(command, *params)
    h.io()
    assert not h.vehicle.commands
    assert _acks(h.api) == [(command, MavResult.DENIED)]


@pytest.mark.parametrize("command, params", [
    (MavCmd.COMPONENT_ARM_DISARM, (1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)),  # 0 is what ground stations send: unset
    (MavCmd.COMPONENT_ARM_DISARM, (1.0, NAN, NAN, NAN, NAN, NAN, NAN)),  # NaN is MAVSDK's unset
    (MavCmd.NAV_TAKEOFF, (-1.0, NAN, NAN, NAN, NAN, NAN, 510.0)),  # QGroundControl's param1 = -1 on a multicopter
    (MavCmd.DO_REPOSITION, (-1.0, 1.0, 5.0, 6.0, 47.0, 8.0, 500.0)),  # not in the table: not checked
])
def test_command_long_with_only_used_params_or_unset_ones_reaches_the_vehicle(h, command, params):
    h.api.command_long(command, *params)
    h.io()
    assert [c.command for c in h.vehicle.commands] == [command]


def test_command_int_with_a_value_in_an_unused_param_is_denied(h):
    h.api.send(h.api.mav.command_int_encode(1, 1, 0, MavCmd.DO_SET_MODE, 0, 0, 1.0, 4.0, 3.0, 0.0, 0, 0, 0.0))
    h.api.send(h.api.mav.command_int_encode(1, 1, 0, MavCmd.DO_SET_MODE, 0, 0, 1.0, 4.0, 3.0, 0.0, 5, 0, 0.0))
    h.io()
    assert [c.command for c in h.vehicle.commands] == [MavCmd.DO_SET_MODE]
    assert _acks(h.api)[-1] == (MavCmd.DO_SET_MODE, MavResult.DENIED)


def test_set_mode_becomes_do_set_mode_and_is_acked_as_176(h):
    h.api.send(h.api.mav.set_mode_encode(1, 1, (3 << 24) | (4 << 16)))
    h.api.send(h.api.mav.set_mode_encode(0, 1, 6 << 16))  # target 0: commander ignores it
    h.io()
    (cmd,) = h.vehicle.commands
    assert cmd.command == MavCmd.DO_SET_MODE and cmd.params[:3] == (1.0, 4.0, 3.0)
    assert _acks(h.api) == [(MavCmd.DO_SET_MODE, MavResult.ACCEPTED)]


# --- setpoints (4.4, 4.7, 4.8) ---------------------------------------------------------------------------------------
def test_position_mask_gives_position_only_and_zero_is_a_value(h):
    _local_ned(h.api, 2552, pos=(0.0, 0.0, -2.5), yaw=0.0)  # MAVSDK position NED: yaw used, yaw rate ignored
    h.io()
    ((mode, traj, att),) = h.vehicle.offboard
    assert (mode.position, mode.velocity, mode.acceleration, mode.attitude) == (True, False, False, True)
    assert traj.position_ned_m == (0.0, 0.0, -2.5)
    assert all(math.isnan(v) for v in traj.velocity_ned_m_s + traj.acceleration_ned_m_s2)
    assert traj.yaw_rad == 0.0 and math.isnan(traj.yawspeed_rad_s) and att is None


def test_mixed_axes_and_velocity_masks(h):
    _local_ned(h.api, 0b110111100011, pos=(9, 9, -3), vel=(1.0, 2.0, 7.0))  # z position + vx,vy velocity
    _local_ned(h.api, 3527, vel=(1.0, -1.0, 0.5))  # MAVROS velocity-only
    h.io()
    (_, t1, _), (m2, t2, _) = h.vehicle.offboard
    assert math.isnan(t1.position_ned_m[0]) and t1.position_ned_m[2] == -3
    assert t1.velocity_ned_m_s[:2] == (1.0, 2.0) and math.isnan(t1.velocity_ned_m_s[2])
    assert m2.velocity and not m2.position and t2.velocity_ned_m_s == (1.0, -1.0, 0.5)


def test_body_ned_velocity_is_rotated_by_yaw_only_and_position_ignored(h):
    h.vehicle.snap_changes = {"euler_rad": (0.3, 0.0, math.pi / 2),
                              "q_wxyz": (math.cos(math.pi / 4), 0.0, 0.0, math.sin(math.pi / 4))}
    _local_ned(h.api, 1479, frame=8, pos=(5, 5, 5), vel=(1.0, 0.0, 0.2), yaw_rate=0.5)  # MAVSDK velocity body
    h.io()
    ((mode, traj, _),) = h.vehicle.offboard
    assert traj.velocity_ned_m_s == pytest.approx((0.0, 1.0, 0.2), abs=1e-6)  # forward = east when facing east
    assert all(math.isnan(v) for v in traj.position_ned_m)
    assert traj.yawspeed_rad_s == 0.5 and math.isnan(traj.yaw_rad) and mode.velocity and mode.body_rate


def test_body_ned_velocity_with_any_ignore_bit_is_dropped_as_invalid(h):
    h.gcs.heartbeat()
    _local_ned(h.gcs, 0b110111000111 | 8, frame=8, vel=(1.0, 0.0, 0.0))  # VX ignored -> no velocity at all
    h.io()
    assert not h.vehicle.offboard
    assert [e.text for e in h.vehicle.events] == ["SET_POSITION_TARGET_LOCAL_NED invalid"]


@pytest.mark.parametrize("frame", [7, 9, 4, 12, 0, 99])
def test_unsupported_frames_are_dropped_with_px4_text(h, frame):
    h.gcs.heartbeat()
    _local_ned(h.api, 2552, frame=frame, pos=(1, 2, -3))
    h.io()
    assert not h.vehicle.offboard
    assert [e.text for e in h.vehicle.events] == [f"SET_POSITION_TARGET_LOCAL_NED coordinate frame {frame} unsupported"]
    chunks = h.gcs.of_type("STATUSTEXT")
    assert "".join(m.text for m in chunks) == f"SET_POSITION_TARGET_LOCAL_NED coordinate frame {frame} unsupported\t"
    assert {m.severity for m in chunks} == {2} and [m.chunk_seq for m in chunks] == [0, 1]
    assert not h.api.of_type("STATUSTEXT"), "no GCS heartbeat on the API link: no STATUSTEXT there"


def test_yaw_only_is_invalid_and_force_is_refused(h):
    _local_ned(h.api, 0b101111111111 & ~1024 | 511, yaw=1.0)  # everything ignored but yaw
    _local_ned(h.api, 0b110000111111 | 512, acc=(0.0, 0.0, -1.0))  # acceleration as force
    h.io()
    assert not h.vehicle.offboard
    assert [e.text for e in h.vehicle.events] == ["SET_POSITION_TARGET_LOCAL_NED invalid",
                                                  "SET_POSITION_TARGET_LOCAL_NED force not supported"]


def test_same_complaint_is_reported_once_per_second(h):
    for _ in range(50):
        _local_ned(h.api, 2552, frame=9)
    h.run(0.5)
    assert len(h.vehicle.events) == 1
    for _ in range(5):
        _local_ned(h.api, 2552, frame=9)
    h.run(0.6)
    assert len(h.vehicle.events) == 1, "within a second of the first"
    _local_ned(h.api, 2552, frame=9)
    h.io()
    assert len(h.vehicle.events) == 2


def test_setpoint_for_another_system_is_ignored(h):
    _local_ned(h.api, 2552, target=(2, 1))
    h.io()
    assert not h.vehicle.offboard


def test_global_int_position_is_projected_into_the_local_frame(h):
    def send(frame, lat, lon, alt, mask=2552):
        h.api.send(h.api.mav.set_position_target_global_int_encode(0, 1, 1, frame, mask, lat, lon, alt,
                                                                   0, 0, 0, 0, 0, 0, 0.5, 0))
    send(5, 473977420 + 900, 85455940, 500.0)  # GLOBAL_INT: 0.00009 deg north ≈ 10 m, alt AMSL
    send(6, 473977420, 85455940 + 1000, 12.0)  # RELATIVE_ALT
    h.gcs.heartbeat()
    send(3, 473977420, 85455940, 12.0)
    h.io()
    (m1, t1, _), (_, t2, _) = h.vehicle.offboard
    assert t1.position_ned_m == pytest.approx((10.007, 0.0, -12.0), abs=0.01)
    assert t2.position_ned_m[1] == pytest.approx(7.53, abs=0.02) and t2.position_ned_m[2] == pytest.approx(-12.0)
    assert t1.yaw_rad == 0.5 and m1.position
    assert [e.text for e in h.vehicle.events] == ["SET_POSITION_TARGET_GLOBAL_INT invalid coordinate frame 3"]


def test_global_int_without_global_position_is_silently_dropped(h):
    h.vehicle.snap_changes = {"position_valid": False}
    h.api.send(h.api.mav.set_position_target_global_int_encode(0, 1, 1, 5, 2552, 473977420, 85455940, 500.0,
                                                               0, 0, 0, 0, 0, 0, 0, 0))
    h.io()
    assert not h.vehicle.offboard and not h.vehicle.events


def test_attitude_target_with_thrust(h):
    q = [math.cos(0.1), math.sin(0.1), 0.0, 0.0]
    h.api.send(h.api.mav.set_attitude_target_encode(0, 1, 1, 0b00000111, q, 0, 0, 0, 0.6))  # attitude + thrust
    h.api.send(h.api.mav.set_attitude_target_encode(0, 1, 1, 0b10000000, q, 0.1, 0.2, 0.3, 0.5))  # rates + thrust
    h.api.send(h.api.mav.set_attitude_target_encode(0, 1, 1, 0b01000111, q, 0, 0, 0, 0.5))  # no thrust: dropped
    h.io()
    (m1, t1, a1), (m2, _, a2) = h.vehicle.offboard
    assert m1.attitude and not m1.body_rate and t1 is None
    assert a1.q_wxyz == pytest.approx(q, abs=1e-6) and a1.thrust_body == pytest.approx((0.0, 0.0, -0.6))
    assert m2.body_rate and not m2.attitude and a2.q_wxyz is None
    assert a2.body_rates_rad_s == pytest.approx((0.1, 0.2, 0.3))


# --- ping, timesync, heartbeat bookkeeping -------------------------------------------------------------------------
def test_ping_to_everyone_is_echoed_back_to_the_sender(h):
    h.api.send(h.api.mav.ping_encode(123456, 7, 0, 0))
    h.api.send(h.api.mav.ping_encode(1, 8, 1, 1))  # a reply to one of ours: not echoed
    h.io()
    (p,) = [m for m in h.api.of_type("PING") if m.target_system != 0]  # the vehicle's own pings go to 0/0
    assert (p.time_usec, p.seq, p.target_system, p.target_component) == (123456, 7, 255, 190)


def test_timesync_request_gets_boot_time_in_ns(h):
    h.run(1.0)
    h.api.send(h.api.mav.timesync_encode(0, 987654321))
    h.io()
    replies = [m for m in h.api.of_type("TIMESYNC") if m.tc1 != 0]
    assert len(replies) == 1 and replies[0].ts1 == 987654321 and replies[0].tc1 == h.vehicle.time_us * 1000


def test_statustext_needs_a_gcs_heartbeat_within_2_5_s(h):
    h.gcs.heartbeat()
    h.api.heartbeat(18)  # an onboard controller (MAVROS) is not a GCS
    h.run(1.0)
    h.vehicle.report(Severity.INFO, "commander", "Armed by external command")
    h.run(0.1)
    assert [m.text for m in h.gcs.of_type("STATUSTEXT")] == ["Armed by external command\t"]
    assert not h.api.of_type("STATUSTEXT")
    h.run(1.5)  # 2.6 s since the GCS heartbeat
    h.vehicle.report(Severity.INFO, "commander", "Disarmed by external command")
    h.run(0.1)
    assert len(h.gcs.of_type("STATUSTEXT")) == 1


def test_texts_wait_for_a_gcs_up_to_5_s(h):
    h.vehicle.report(Severity.INFO, "commander", "Ready for takeoff!")
    h.run(2.0)
    h.vehicle.report(Severity.INFO, "commander", "Takeoff detected")
    h.run(3.5)  # the first text is now 5.5 s old, the second 3.5 s
    assert not h.gcs.of_type("STATUSTEXT")
    h.gcs.heartbeat()
    h.io()
    assert [m.text for m in h.gcs.of_type("STATUSTEXT")] == ["Takeoff detected\t"]


def test_long_statustext_is_chunked_with_one_id(h):
    h.gcs.heartbeat()
    h.vehicle.report(Severity.WARNING, "commander", "x" * 60 + "y" * 50)
    h.vehicle.report(Severity.INFO, "commander", "short")
    h.io()
    msgs = h.gcs.of_type("STATUSTEXT")
    assert [(m.id, m.chunk_seq) for m in msgs] == [(0, 0), (0, 1), (0, 2), (1, 0)]
    assert "".join(m.text for m in msgs[:3]) == "x" * 60 + "y" * 50 + "\t"


def test_our_own_looped_back_messages_are_ignored(h):
    own = Client(sysid=1, compid=1)
    own.target = h.api.target
    try:
        own.command_long(MavCmd.COMPONENT_ARM_DISARM, 1.0)
        h.io()
        assert not h.vehicle.commands
    finally:
        own.close()


def test_boot_state_for_reference():
    assert FakeVehicle().snapshot().nav_state == NavState.AUTO_LOITER
