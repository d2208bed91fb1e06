"""MAVSDK's LogFiles plugin (what QGroundControl-like tools use) lists and downloads a log `serve` wrote, byte for byte.

The log is a real one: a short flight of a Sim with logging on (arm on the ground, hold, disarm), put where `serve`
keeps its logs (log/ of its working directory). Skipped only when MAVSDK cannot be loaded here.
"""

from __future__ import annotations

import asyncio
import math
import shutil
from pathlib import Path
from typing import Any

import pytest
from support.serve_process import load_mavsdk, serve

from sitl_emu.px4 import MavCmd
from sitl_emu.testing.sim import Sim
from sitl_emu.types import VehicleCommand

pytestmark = pytest.mark.slow  # processes or long flights: not in `make test-fast`

SPEED = 4.0
CALL_TIMEOUT_S = 60.0
NAN = math.nan


def _write_a_log(log_dir: Path) -> Path:
    with Sim(log_dir=log_dir) as sim:
        vehicle = sim.vehicle(0)
        sim.run_for(3.0)
        vehicle.handle_command(VehicleCommand(MavCmd.COMPONENT_ARM_DISARM, (1.0, 0.0) + (NAN,) * 5))
        sim.run_for(2.0)
        vehicle.handle_command(VehicleCommand(MavCmd.COMPONENT_ARM_DISARM, (0.0, 21196.0) + (NAN,) * 5))
        sim.run_for(0.1)
        (path,) = sim.loggers[0].files
    return path


@pytest.mark.timeout(240)
def test_mavsdk_log_files_lists_and_downloads_a_log_byte_for_byte(tmp_path):
    mavsdk_asyncio = load_mavsdk()
    work = tmp_path / "work"
    written = _write_a_log(tmp_path / "sim-logs")
    served_copy = work / "log" / written.parent.name / written.name
    served_copy.parent.mkdir(parents=True)
    shutil.copyfile(written, served_copy)
    with serve(work, tmp_path / "serve.log", SPEED) as ports:
        out = tmp_path / "downloaded.ulg"
        download = _download(mavsdk_asyncio, ports.api_remote, out, written.stat().st_size)
        asyncio.run(asyncio.wait_for(download, timeout=200))
    assert out.read_bytes() == written.read_bytes()


async def _call(awaitable: Any) -> Any:
    return await asyncio.wait_for(awaitable, CALL_TIMEOUT_S)


async def _download(mavsdk_asyncio: Any, port: int, out: Path, size: int) -> None:
    from mavsdk.asyncio.plugins.log_files import LogFilesAsync

    config = mavsdk_asyncio.Configuration.create_with_component_type(mavsdk_asyncio.ComponentType.GROUND_STATION)
    async with mavsdk_asyncio.Mavsdk(config) as mavsdk:
        await _call(mavsdk.add_any_connection(f"udpin://0.0.0.0:{port}"))
        system = await asyncio.wait_for(mavsdk.first_autopilot(timeout_s=20.0), 25.0)
        assert system is not None, "MAVSDK found no autopilot"
        log_files = LogFilesAsync(system)
        entries = await _call(log_files.get_entries())
        # the copied log, and serve's own log running since its boot (SDLOG_MODE 1, as PX4 SITL lists its own)
        (entry,) = [e for e in entries if e.size_bytes == size]
        async for _ in log_files.download_log_file(entry, str(out)):
            pass
