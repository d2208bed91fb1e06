"""`listener <topic> [-n N]` in the pxh> shell: PX4's output format, PX4's field names, values of the vehicle."""

from __future__ import annotations

import itertools
import re

import pytest
from support.handler_ctx import FakeVehicle, make_snapshot

from sitl_emu.console.shell import Shell
from sitl_emu.px4 import NavState
from sitl_emu.vehicle.vehicle import Vehicle

S = 1_000_000


def _fields(text: str) -> dict[str, str]:
    """'    name: value' lines of one message -> {name: value} (with the ' (... ago)' remarks)."""
    return dict(re.findall(r"^    (\w+): (.*)$", text, flags=re.M))


def _run(vehicle: Vehicle, seconds: float) -> None:
    for _ in range(round(seconds * S / vehicle.dt_us)):
        vehicle.step()


def test_local_position_prints_px4_header_and_fields_in_px4_order():
    vehicle = FakeVehicle()
    vehicle.time_us = 5_000_000
    vehicle.snap = make_snapshot(time_us=5_000_000, pos_ned_m=(1.5, -2.25, -3.0), vel_ned_m_s=(0.5, 0.0, -1.0),
                                 euler_rad=(0.0, 0.0, 1.25))
    out = Shell(vehicle).execute("listener vehicle_local_position")
    assert out.startswith("\nTOPIC: vehicle_local_position\n vehicle_local_position\n    timestamp: 5000000 "
                          "(0.000000 seconds ago)\n    timestamp_sample: 5000000 (0 us before timestamp)\n")
    fields = _fields(out)
    names = list(fields)
    # PX4's uORB field order (px4-ulog-topics.txt), for the fields sitl_emu models
    assert names == ["timestamp", "timestamp_sample", "ref_lat", "ref_lon", "x", "y", "z", "vx", "vy", "vz",
                     "z_deriv", "ax", "ay", "az", "heading", "ref_alt", "xy_valid", "z_valid", "v_xy_valid",
                     "v_z_valid", "xy_global", "z_global"]
    assert (fields["x"], fields["y"], fields["z"]) == ("1.50000", "-2.25000", "-3.00000")  # float: %.5f
    assert (fields["vx"], fields["vz"], fields["z_deriv"]) == ("0.50000", "-1.00000", "-1.00000")
    assert fields["heading"] == "1.25000"
    assert fields["ref_lat"] == "47.397742"  # double: %.6f
    assert fields["xy_valid"] == "True"


def test_timestamp_says_how_long_ago_on_simulated_time():
    vehicle = FakeVehicle()
    vehicle.snap = make_snapshot(time_us=2_000_000)
    vehicle.time_us = 2_250_000
    fields = _fields(Shell(vehicle).execute("listener battery_status"))
    assert fields["timestamp"] == "2000000 (0.250000 seconds ago)"


def test_vehicle_status_fields_with_px4_numbers():
    vehicle = FakeVehicle(sysid=3)
    vehicle.snap = make_snapshot(armed=True, nav_state=NavState.OFFBOARD, user_intended_nav_state=NavState.OFFBOARD)
    fields = _fields(Shell(vehicle).execute("listener vehicle_status"))
    assert fields["arming_state"] == "2"  # ARMING_STATE_ARMED (VehicleStatus.msg)
    assert fields["nav_state"] == "14" and fields["nav_state_user_intention"] == "14"
    assert fields["system_id"] == "3" and fields["component_id"] == "1"
    assert fields["failsafe"] == "False" and fields["pre_flight_checks_pass"] == "True"


def test_battery_status_fields():
    fields = _fields(Shell(FakeVehicle()).execute("listener battery_status"))
    assert fields["voltage_v"] == "16.20000" and fields["remaining"] == "1.00000"
    assert fields["connected"] == "True" and fields["cell_count"] == "4"


def test_values_follow_the_real_vehicle_through_a_takeoff():
    vehicle = Vehicle()
    shell = Shell(vehicle)
    _run(vehicle, 3.0)  # estimator ready
    before = _fields(shell.execute("listener vehicle_local_position"))
    status = _fields(shell.execute("listener vehicle_status"))
    assert status["arming_state"] == "1" and status["nav_state"] == str(int(NavState.AUTO_LOITER))
    assert abs(float(before["z"])) < 0.1
    shell.execute("commander takeoff")
    _run(vehicle, 15.0)
    after = _fields(shell.execute("listener vehicle_local_position"))
    status = _fields(shell.execute("listener vehicle_status"))
    snap = vehicle.snapshot()
    assert float(after["z"]) == pytest.approx(snap.pos_ned_m[2], abs=1e-5)
    assert float(after["z"]) == pytest.approx(-2.5, abs=0.3)  # MIS_TAKEOFF_ALT above the ground
    assert after["timestamp"].startswith(f"{vehicle.time_us} ")
    assert status["arming_state"] == "2"


def test_unknown_topic_gets_px4s_answer_and_fails():
    out = Shell(FakeVehicle()).execute("listener sensor_nonsense")
    assert out.startswith("Topic sensor_nonsense did not match any known topics\n")
    assert "vehicle_local_position" in out  # what it can show instead
    assert out.endswith("Command 'listener' failed, returned -1.\n")


@pytest.mark.parametrize("line", ["listener", "listener vehicle_status -n", "listener vehicle_status -x 1",
                                  "listener vehicle_status -n many", "listener vehicle_status -n 101"])
def test_bad_arguments_print_usage(line):
    out = Shell(FakeVehicle()).execute(line)
    assert out.startswith("Usage: listener <command> [arguments...]\n")
    assert out.endswith("Command 'listener' failed, returned 1.\n")


def test_other_instances_were_never_published():
    assert Shell(FakeVehicle()).execute("listener vehicle_status -i 1") == "never published\n"


def test_n_messages_come_one_per_publication_on_simulated_time():
    vehicle = Vehicle()
    shell = Shell(vehicle)
    out = shell.execute("listener vehicle_local_position -n 3")
    assert out.startswith("\nTOPIC: vehicle_local_position instance 0 #1\n vehicle_local_position\n")
    assert shell.busy
    assert shell.poll() == ""  # no time passed: nothing new published
    times = [vehicle.time_us]
    while shell.busy:
        vehicle.step()
        text = shell.poll()
        if text:
            times.append(vehicle.time_us)
            assert f"TOPIC: vehicle_local_position instance 0 #{len(times)}\n" in text
            assert _fields(text)["timestamp"].startswith(f"{vehicle.time_us} ")
    assert len(times) == 3
    assert [b - a for a, b in itertools.pairwise(times)] == [8_000, 8_000]  # 125 Hz, as in PX4 SITL


def test_vehicle_status_is_published_at_2_hz_and_at_once_on_a_change():
    vehicle = FakeVehicle()
    shell = Shell(vehicle)
    shell.execute("listener vehicle_status -n 3")
    vehicle.time_us = 100_000
    assert shell.poll() == ""
    vehicle.snap = make_snapshot(time_us=100_000, armed=True)
    assert "#2" in shell.poll()  # changed: published at once
    vehicle.time_us = 400_000
    assert shell.poll() == ""
    vehicle.time_us = 600_000
    assert "#3" in shell.poll()  # 500 ms later
    assert not shell.busy


def test_a_new_command_stops_a_running_listener():
    vehicle = FakeVehicle()
    shell = Shell(vehicle)
    shell.execute("listener vehicle_status -n 5")
    assert shell.busy
    shell.execute("ver")
    assert not shell.busy


def test_help_lists_listener():
    assert "  listener\n" in Shell(FakeVehicle()).execute("help")
