"""A flight in lockstep over loopback with logging on: the ULog file pyulog and PX4's tools read back.

One takeoff-and-land flight (flight.py) is flown for the module; the file must hold PX4's topics with PX4's field
names, the flight as the link reported it (positions, texts), the parameters (one changed in flight) and the infos,
and be served byte for byte by LOG_REQUEST_LIST / LOG_REQUEST_DATA.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from support.log_flight import TAKEOFF_ALT_M, Flight, fly_takeoff_land, log_files

from sitl_emu.log.topics import default_topics
from sitl_emu.mavlink.protocols.log import LIST_ALL

pytestmark = pytest.mark.slow  # processes or long flights: not in `make test-fast`

pyulog = pytest.importorskip("pyulog", reason="pyulog reads the logs back: pip install pyulog (the test extra)")
ULog = pyulog.ULog

ARMING_STATE_ARMED = 2


@pytest.fixture(scope="module")
def flight(tmp_path_factory: pytest.TempPathFactory):
    f = fly_takeoff_land(tmp_path_factory.mktemp("logs"))
    yield f
    f.sim.close()


@pytest.fixture(scope="module")
def ulog(flight: Flight):
    files = log_files(flight.log_dir)
    assert len(files) == 1, files
    return ULog(str(files[0]))


def _topic(ulog, name: str):
    return ulog.get_dataset(name).data


def test_one_flight_is_one_valid_log_from_arming_to_disarming(flight, ulog):
    assert not ulog.file_corruption
    status = _topic(ulog, "vehicle_status")
    armed = status["arming_state"] == ARMING_STATE_ARMED
    assert armed[0] and not armed[-1]  # opened armed, the last message is the disarmed state
    assert np.all(armed[:-1])
    texts = [m.message for m in ulog.logged_messages]
    assert texts[0] == "Armed by external command\t" and texts[-1] == "Disarmed by landing\t"
    assert flight.sim.loggers[0].files == log_files(flight.log_dir) and not flight.sim.loggers[0].writing


def test_topics_and_fields_have_px4_names(ulog):
    logged = {d.name: set(d.data) for d in ulog.data_list}
    for topic in default_topics():
        if topic.name in ("manual_control_setpoint", "offboard_control_mode"):  # no joystick, no offboard here
            assert topic.name not in logged
            continue
        assert topic.name in logged, topic.name
        expected = {f"{f.name}[{i}]" if f.count else f.name for f in topic.format.fields
                    if not f.name.startswith("_padding") for i in range(max(f.count, 1))}
        assert logged[topic.name] == expected
    for name in ("vehicle_local_position", "vehicle_attitude", "vehicle_global_position", "actuator_motors",
                 "vehicle_local_position_setpoint", "vehicle_rates_setpoint", "battery_status", "vehicle_status"):
        assert name in logged


def test_topics_are_logged_at_px4_rates(ulog):
    def rate(name: str) -> float:
        t = _topic(ulog, name)["timestamp"]
        return (len(t) - 1) / ((t[-1] - t[0]) / 1e6)

    assert rate("vehicle_attitude") == pytest.approx(250, rel=0.02)  # every update (SDLOG_PROFILE 131)
    assert rate("vehicle_local_position") == pytest.approx(125, rel=0.02)
    assert rate("vehicle_angular_velocity") == pytest.approx(100, rel=0.05)
    assert rate("actuator_motors") == pytest.approx(10, rel=0.05)
    assert rate("battery_status") == pytest.approx(5, rel=0.05)


def test_position_trace_is_what_local_position_ned_said(flight, ulog):
    lp = _topic(ulog, "vehicle_local_position")
    by_ms = {int(t) // 1000: i for i, t in enumerate(lp["timestamp"]) if int(t) % 1000 == 0}
    matched = 0
    for msg in flight.client.received["LOCAL_POSITION_NED"]:
        i = by_ms.get(msg.time_boot_ms)
        if i is None:
            continue
        matched += 1
        assert (lp["x"][i], lp["y"][i], lp["z"][i]) == (np.float32(msg.x), np.float32(msg.y), np.float32(msg.z))
        assert (lp["vx"][i], lp["vz"][i]) == (np.float32(msg.vx), np.float32(msg.vz))
    assert matched > 100
    assert -lp["z"].min() == pytest.approx(TAKEOFF_ALT_M, abs=0.3)  # the altitude profile: up to the takeoff altitude
    assert abs(lp["z"][0]) < 0.1 and abs(lp["z"][-1]) < 0.1  # from the ground, back on the ground


def test_parameters_and_infos(ulog):
    info = ulog.msg_info_dict
    assert info["sys_name"] == "PX4" and info["ver_hw"] == "PX4_SITL" and info["ver_sw"]
    assert "sys_uuid" in info and "ver_sw_release" in info
    params = ulog.initial_parameters
    assert len(params) > 900
    assert params["MIS_TAKEOFF_ALT"] == pytest.approx(TAKEOFF_ALT_M)
    assert isinstance(params["MAV_SYS_ID"], int) and params["MAV_SYS_ID"] == 1
    assert [(name, value) for _, name, value in ulog.changed_parameters] == [("MPC_XY_VEL_MAX", pytest.approx(7.5))]
    system_defaults = ulog.get_default_parameters(0)  # PX4's 'Q': the defaults of what differs from them
    assert system_defaults["MIS_TAKEOFF_ALT"] == pytest.approx(2.5)


def test_every_statustext_is_a_logged_string_at_its_level(flight, ulog):
    logged = [(m.log_level_str(), m.message[:50]) for m in ulog.logged_messages]
    sent = [("INFO" if m.severity == 6 else str(m.severity), m.text) for m in flight.client.received["STATUSTEXT"]
            if m.chunk_seq == 0]
    assert logged == sent
    path = log_files(flight.log_dir)[0]
    assert f"[logger] {path}\t" in [m.message for m in ulog.logged_messages]  # the file, as the text names it


@pytest.mark.parametrize("tool", ["ulog_info", "ulog_params"])
def test_pyulog_command_line_tools_read_it(flight, tool):
    exe = shutil.which(tool) or str(Path(sys.executable).parent / tool)
    out = subprocess.run([exe, str(log_files(flight.log_dir)[0])], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert ("sys_name: PX4" in out.stdout) if tool == "ulog_info" else ("MIS_TAKEOFF_ALT" in out.stdout)


def test_log_download_returns_the_same_bytes(flight):
    c = flight.client
    path = log_files(flight.log_dir)[0]
    c.send(c.mav.log_request_list_encode(1, 1, 0, LIST_ALL))
    c.wait(lambda: bool(c.received["LOG_ENTRY"]), 2.0, "LOG_ENTRY")
    entry = c.received["LOG_ENTRY"][-1]
    assert (entry.id, entry.num_logs, entry.size) == (0, 1, path.stat().st_size)
    c.send(c.mav.log_request_data_encode(1, 1, 0, 0, 0xFFFFFFFF))
    data = bytearray()

    def complete() -> bool:
        for m in c.received.pop("LOG_DATA", []):
            assert m.ofs == len(data)
            data.extend(bytes(m.data[:m.count]))
        return len(data) >= entry.size

    c.wait(complete, 60.0, "the whole log")
    assert bytes(data) == path.read_bytes()


def test_same_seed_same_data(flight, ulog, tmp_path):
    again = fly_takeoff_land(tmp_path)
    try:
        other = ULog(str(log_files(tmp_path)[0]))
    finally:
        again.sim.close()
    for name in ("vehicle_local_position", "vehicle_attitude", "actuator_motors"):
        a, b = _topic(ulog, name), _topic(other, name)
        assert a.keys() == b.keys()
        for key in a:
            np.testing.assert_array_equal(a[key], b[key], err_msg=f"{name}.{key}")


def _two_flights(log_dir: Path, mode: int) -> tuple[list[Path], list[list[str]]]:
    """Boot, arm, disarm, arm, disarm on the ground (SDLOG_MODE `mode`): the files and each file's logged texts."""
    from sitl_emu.px4 import MavCmd
    from sitl_emu.testing.sim import Sim
    from sitl_emu.types import VehicleCommand

    nan = float("nan")
    with Sim(log_dir=log_dir, params={"SDLOG_MODE": mode}) as sim:
        vehicle = sim.vehicle(0)
        sim.run_for(3.0)
        for _ in range(2):
            vehicle.handle_command(VehicleCommand(MavCmd.COMPONENT_ARM_DISARM, (1.0, 0.0) + (nan,) * 5))
            sim.run_for(1.0)
            vehicle.handle_command(VehicleCommand(MavCmd.COMPONENT_ARM_DISARM, (0.0, 21196.0) + (nan,) * 5))
            sim.run_for(1.0)
        files = list(sim.loggers[0].files)
        sim.loggers[0].close()
    return files, [[m.message for m in ULog(str(f)).logged_messages] for f in files]


@pytest.mark.parametrize(("mode", "count"), [(-1, 0), (0, 2), (1, 2), (2, 1), (4, 1)])
def test_sdlog_mode_says_when_logs_begin_and_end(tmp_path, mode, count):
    """logger.cpp start_stop_logging: 0 a log per flight; 1 (PX4 SITL's) the first from boot to the first disarming,
    so the first arming logs no "[logger]" text (px4-mission cases.json: flight1.arm none, flight2.arm one); 2 one
    log from boot to shutdown; 4 one from the first arming on; -1 none."""
    files, texts = _two_flights(tmp_path, mode)
    assert len(files) == count
    if mode == 1:
        assert texts[0][0].startswith("[logger]") and texts[0][1] == "Armed by external command\t"
        assert texts[0][-1].startswith("Disarmed by") and texts[1][0] == "Armed by external command\t"
        assert texts[1][1].startswith("[logger]")
    if mode in (2, 4):
        assert sum(t.startswith("Armed by") for t in texts[0]) == 2
