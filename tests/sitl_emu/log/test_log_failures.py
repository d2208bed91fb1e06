"""A log that cannot be written never costs the flight: one warning, the vehicle flies on, the next arming tries again.

Also: the sticks of a MAVLink joystick are logged as manual_control_setpoint while they are valid.
"""

from __future__ import annotations

import logging
from pathlib import Path

import pytest
from support.log_flight import fly_takeoff_land, log_files

from sitl_emu.log.flight_log import BUFFER_BYTES
from sitl_emu.mavlink.protocols.log import LIST_ALL
from sitl_emu.types import ManualControlSetpoint

pyulog = pytest.importorskip("pyulog", reason="pyulog reads the logs back: pip install pyulog (the test extra)")

LOGGER = "sitl_emu.log.flight_log"


def _warnings(caplog: pytest.LogCaptureFixture) -> list[str]:
    return [r.getMessage() for r in caplog.records if r.name == LOGGER and r.levelno == logging.WARNING]


@pytest.mark.slow
def test_an_unwritable_log_directory_is_one_warning_and_the_flight_goes_on(tmp_path, caplog):
    blocker = tmp_path / "not-a-directory"
    blocker.write_text("a file where the log directory should be")
    with caplog.at_level(logging.WARNING, logger=LOGGER):
        flight = fly_takeoff_land(blocker / "log")  # lands and disarms: the flight itself is whole
    try:
        c = flight.client
        assert [m for m in c.received["STATUSTEXT"] if m.text.startswith("[logger]")] == []
        assert "Disarmed by landing\t" in [m.text for m in c.received["STATUSTEXT"]]
        warnings = _warnings(caplog)
        assert len(warnings) == 1 and "the flight goes on without a log" in warnings[0], warnings
        c.send(c.mav.log_request_list_encode(1, 1, 0, LIST_ALL))  # and there is no log to list
        c.wait(lambda: bool(c.received["LOG_ENTRY"]), 2.0, "LOG_ENTRY")
        assert c.received["LOG_ENTRY"][-1].num_logs == 0
    finally:
        flight.sim.close()


@pytest.mark.slow
def test_a_full_disk_ends_the_log_with_one_warning_and_the_next_flight_logs_again(tmp_path, caplog, monkeypatch):
    def full_disk(path: Path):
        path.write_bytes(b"")  # the name is taken, the data never lands (/dev/full: ENOSPC on every write)
        return open("/dev/full", "wb", buffering=BUFFER_BYTES)  # the logger closes it

    if not Path("/dev/full").exists():
        pytest.skip("needs /dev/full to simulate a full disk")
    monkeypatch.setattr("sitl_emu.log.flight_log._open_file", full_disk)
    with caplog.at_level(logging.WARNING, logger=LOGGER):
        flight = fly_takeoff_land(tmp_path, change_param=False)
    try:
        assert "Disarmed by landing\t" in [m.text for m in flight.client.received["STATUSTEXT"]]
        warnings = _warnings(caplog)
        assert len(warnings) == 1 and "No space left on device" in warnings[0], warnings
        logger = flight.sim.loggers[0]
        assert not logger.writing
        monkeypatch.undo()  # space again: the next arming writes a whole log
        logger.opener = lambda path: path.open("xb")
        c = flight.client
        c.command(400, 1)  # MAV_CMD_COMPONENT_ARM_DISARM: arm on the ground ...
        c.wait(lambda: c.armed, 5.0, "armed again")
        c.command(400, 0)  # ... and disarm
        c.wait(lambda: not c.armed, 5.0, "disarmed again")
        assert len(logger.files) == 2 and not logger.writing
        assert not pyulog.ULog(str(logger.files[1])).file_corruption
    finally:
        flight.sim.close()


def test_sticks_are_logged_as_manual_control_setpoint(tmp_path):
    from sitl_emu.testing.sim import Sim

    with Sim(log_dir=tmp_path) as sim:
        vehicle = sim.vehicle(0)
        sim.run_until(lambda: vehicle.snapshot().pre_flight_checks_pass, 30.0)
        sticks = ManualControlSetpoint(roll=0.25, pitch=-0.5, yaw=0.0, throttle=0.0, buttons=3)
        vehicle.manual_control_input(sticks)
        sim.run_for(0.1)
        from sitl_emu.px4 import MavCmd
        from sitl_emu.types import VehicleCommand
        vehicle.handle_command(VehicleCommand(MavCmd.COMPONENT_ARM_DISARM, (1.0, 0.0) + (float("nan"),) * 5))
        for _ in range(10):
            vehicle.manual_control_input(sticks)
            sim.run_for(0.1)
        vehicle.handle_command(VehicleCommand(MavCmd.COMPONENT_ARM_DISARM, (0.0, 21196.0) + (float("nan"),) * 5))
        sim.run_for(0.1)
    files = log_files(tmp_path)
    assert len(files) == 1
    manual = pyulog.ULog(str(files[0])).get_dataset("manual_control_setpoint").data
    assert len(manual["timestamp"]) >= 4  # 5 Hz (logged_topics.cpp: 200 ms) over ~1 s
    assert set(manual["roll"]) == {0.25} and set(manual["pitch"]) == {-0.5} and set(manual["buttons"]) == {3}
