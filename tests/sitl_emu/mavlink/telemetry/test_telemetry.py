"""What a client sees of the real Vehicle: PX4's heartbeat, mode numbers, stream sets and rates, message contents."""

from __future__ import annotations

import math
from collections import Counter

import pytest
from pymavlink import mavutil
from support.fakes import HOME, Harness

from sitl_emu.px4 import MavCmd
from sitl_emu.vehicle.vehicle import Vehicle

EPOCH_US = 1_700_000_000_000_000


@pytest.fixture
def h():
    harness = Harness(Vehicle(home=HOME), epoch_unix_us=EPOCH_US)
    yield harness
    harness.close()


def _last(client, msg_type):
    return client.of_type(msg_type)[-1]


def _stream_setpoints(h, z=-3.0):
    h.api.send(h.api.mav.set_position_target_local_ned_encode(0, 1, 1, 1, 2552, 0, 0, z, 0, 0, 0, 0, 0, 0, 0, 0))


def test_boot_heartbeat_is_px4_sitl_hold_uninit_then_standby_once_ready(h):
    h.io()
    first = _last(h.api, "HEARTBEAT")
    assert (first.type, first.autopilot, first.mavlink_version) == (2, 12, 3)
    assert (first.base_mode, first.custom_mode, first.system_status) == (29, 50593792, 0)
    h.run(3.0)
    ready = _last(h.api, "HEARTBEAT")
    assert (ready.base_mode, ready.custom_mode, ready.system_status) == (29, 50593792, 3)
    assert mavutil.interpret_px4_mode(ready.base_mode, ready.custom_mode) == "LOITER"
    assert _last(h.gcs, "HEARTBEAT").custom_mode == 50593792


@pytest.mark.parametrize("name", ["TAKEOFF", "OFFBOARD", "RTL", "LAND", "MISSION", "LOITER"])
def test_pymavlink_px4_mode_map_round_trips_through_do_set_mode(h, name):
    base_mode, main, sub = mavutil.px4_map[name]
    h.run(2.5)
    h.api.command_long(MavCmd.DO_SET_MODE, base_mode, main, sub)
    h.run(1.1)
    assert [(a.command, a.result) for a in h.api.of_type("COMMAND_ACK")] == [(MavCmd.DO_SET_MODE, 0)]
    hb = _last(h.api, "HEARTBEAT")
    assert mavutil.interpret_px4_mode(hb.base_mode, hb.custom_mode) == name
    assert hb.custom_mode == (sub << 24) | (main << 16)


def test_base_mode_offboard_is_1_without_setpoints_17_with_and_145_armed(h):
    h.run(2.5)
    h.api.command_long(MavCmd.DO_SET_MODE, 1, 6, 0)
    h.run(1.0)
    assert _last(h.api, "HEARTBEAT").base_mode == 1
    every = {"n": 0}

    def stream():
        every["n"] += 1
        if every["n"] % 12 == 0:
            _stream_setpoints(h)
    h.run(1.0, stream)
    assert _last(h.api, "HEARTBEAT").base_mode == 17
    h.api.command_long(MavCmd.COMPONENT_ARM_DISARM, 1.0)
    h.run(1.0, stream)
    hb = _last(h.api, "HEARTBEAT")
    assert (hb.base_mode, hb.system_status) == (145, 4)
    assert mavutil.interpret_px4_mode(hb.base_mode, hb.custom_mode) == "OFFBOARD"


# Rates in Hz per link: PX4 onboard defaults on the API link, normal + SITL overrides on the GCS link.
API_RATES = {"HEARTBEAT": 1, "ATTITUDE": 100, "ATTITUDE_QUATERNION": 50, "LOCAL_POSITION_NED": 30,
             "GLOBAL_POSITION_INT": 50, "ODOMETRY": 30, "TIMESYNC": 10, "ALTITUDE": 10, "VFR_HUD": 10,
             "GPS_RAW_INT": 8, "SYS_STATUS": 5, "EXTENDED_SYS_STATE": 5, "SYSTEM_TIME": 1, "PING": 1}
GCS_RATES = {"HEARTBEAT": 1, "ATTITUDE": 50, "ATTITUDE_QUATERNION": 50, "LOCAL_POSITION_NED": 50,
             "GLOBAL_POSITION_INT": 50, "VFR_HUD": 4, "GPS_RAW_INT": 5, "SYS_STATUS": 1, "EXTENDED_SYS_STATE": 1,
             "ALTITUDE": 1, "PING": 0.1}


def test_stream_sets_and_rates_per_link(h):
    h.run(3.0)
    n_api, n_gcs = len(h.api.received), len(h.gcs.received)
    h.run(4.0)
    api = Counter(m.get_type() for m in h.api.received[n_api:])
    gcs = Counter(m.get_type() for m in h.gcs.received[n_gcs:])
    for name, hz in API_RATES.items():
        assert api[name] == pytest.approx(4 * hz, abs=1), name
    for name, hz in GCS_RATES.items():
        assert gcs[name] == pytest.approx(4 * hz, abs=1), name
    for absent in ("ODOMETRY", "TIMESYNC", "SYSTEM_TIME"):
        assert gcs[absent] == 0, f"{absent} is not in the normal-mode set"
    assert api["HOME_POSITION"] == 2 and gcs["HOME_POSITION"] == 2  # 0.5 Hz, once home is valid


def test_home_position_only_once_valid_and_global_position_matches_home(h):
    h.run(1.5)
    assert not h.api.of_type("HOME_POSITION") and not h.gcs.of_type("HOME_POSITION")
    h.run(3.0)
    home = _last(h.api, "HOME_POSITION")
    assert (home.latitude, home.longitude) == (round(HOME[0] * 1e7), round(HOME[1] * 1e7))
    assert home.altitude == pytest.approx(HOME[2] * 1000, abs=50)
    gpi = _last(h.api, "GLOBAL_POSITION_INT")
    assert abs(gpi.lat - home.latitude) < 20 and abs(gpi.lon - home.longitude) < 20
    assert abs(gpi.relative_alt) < 100 and gpi.alt == pytest.approx(HOME[2] * 1000, abs=100)


def test_sys_status_health_bits_mavsdk_reads(h):
    h.run(0.5)
    early = _last(h.api, "SYS_STATUS")
    assert not early.onboard_control_sensors_health & 0x20, "no GPS health before the estimator is ready"
    assert not early.onboard_control_sensors_health & 0x10000000
    h.run(2.5)
    s = _last(h.api, "SYS_STATUS")
    for bit in (0x01, 0x02, 0x04, 0x20):  # gyro, accel, mag, GPS
        assert s.onboard_control_sensors_present & bit and s.onboard_control_sensors_health & bit, hex(bit)
    # PREARM_CHECK is a health bit only (PX4 SIH: present 0x0300c02f, health 0x1320c83f)
    assert s.onboard_control_sensors_health & 0x10000000 and not s.onboard_control_sensors_present & 0x10000000
    assert s.voltage_battery > 10000 and 0 < s.battery_remaining <= 100


def test_landed_state_timesync_and_system_time(h):
    h.run(2.0)
    assert _last(h.api, "EXTENDED_SYS_STATE").landed_state == 1
    ts = _last(h.api, "TIMESYNC")
    assert ts.tc1 == 0 and 0 < ts.ts1 <= h.vehicle.time_us * 1000
    st = _last(h.api, "SYSTEM_TIME")
    assert st.time_unix_usec - EPOCH_US == st.time_boot_ms * 1000
    vfr = _last(h.gcs, "VFR_HUD")
    assert vfr.throttle == 0 and vfr.alt == pytest.approx(HOME[2], abs=0.2) and math.isnan(vfr.airspeed)


@pytest.mark.slow
def test_offboard_flight_reports_setpoint_and_intended_mode(h):
    n = {"i": 0}

    def stream():
        n["i"] += 1
        if n["i"] % 12 == 0:
            _stream_setpoints(h, z=-3.0)
    h.run(2.5, stream)
    h.api.command_long(MavCmd.COMPONENT_ARM_DISARM, 1.0)
    h.api.command_long(MavCmd.DO_SET_MODE, 1, 6, 0)
    h.run(8.0, stream)
    target = _last(h.gcs, "POSITION_TARGET_LOCAL_NED")
    assert target.coordinate_frame == 1 and target.z == pytest.approx(-3.0, abs=0.05)
    assert _last(h.api, "LOCAL_POSITION_NED").z == pytest.approx(-3.0, abs=0.3)
    assert _last(h.api, "EXTENDED_SYS_STATE").landed_state == 2
    h.run(4.0)  # stream stopped: offboard loss -> RTL, the user's intention stays OFFBOARD
    assert _last(h.api, "HEARTBEAT").custom_mode == 84148224
    modes = [(m.custom_mode, m.intended_custom_mode) for m in h.api.of_type("CURRENT_MODE")]
    assert modes[-1] == (84148224, 393216)


def test_imu_and_barometer_at_rest_read_gravity_and_isa_pressure(h):
    h.run(1.0)
    imu = _last(h.api, "HIGHRES_IMU")
    assert (imu.xacc, imu.yacc) == pytest.approx((0.0, 0.0), abs=0.05) and imu.zacc == pytest.approx(-9.81, abs=0.05)
    assert imu.abs_pressure == pytest.approx(955.0, abs=2.0)  # ISA at 488 m
    assert imu.xmag > 0 and imu.zmag > 0  # northern hemisphere: field points north and down
    assert len(h.api.of_type("HIGHRES_IMU")) == pytest.approx(50, abs=2)
    assert not h.gcs.of_type("HIGHRES_IMU"), "not in the normal-mode set"
    assert _last(h.gcs, "SCALED_PRESSURE").press_abs == pytest.approx(imu.abs_pressure)


def test_reboot_restarts_simulated_time_and_the_streams_carry_on(h):
    h.gcs.heartbeat()
    h.run(3.0)
    h.gcs.command_long(MavCmd.PREFLIGHT_REBOOT_SHUTDOWN, 1)  # param1 1: reboot the autopilot
    h.run(0.1)
    assert [(a.command, a.result) for a in h.gcs.of_type("COMMAND_ACK")] == [(MavCmd.PREFLIGHT_REBOOT_SHUTDOWN, 0)]
    assert h.vehicle.time_us < 200_000, "time starts again at boot"
    n_hb = len(h.api.of_type("HEARTBEAT"))
    h.run(3.0)
    after = h.api.of_type("HEARTBEAT")[n_hb:]
    assert len(after) == 3 and after[0].system_status == 0 and after[-1].system_status == 3
    assert len([m for m in h.api.received[-400:] if m.get_type() == "ATTITUDE"]) > 50
