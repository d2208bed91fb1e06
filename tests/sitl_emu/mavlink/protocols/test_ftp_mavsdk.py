"""Conformance: MAVSDK's Ftp and LogFiles plugins (the native `mavsdk` >= 4 binding) against `sitl-emu serve`.

The server runs in a scratch working directory, so its FTP root is that directory's fs/ (as PX4 SITL serves its
own working directory). MAVSDK lists it, downloads with and without burst, uploads, compares by CRC32, makes and
removes a directory, renames and removes a file, is refused a path out of the root, and its LogFiles plugin gets
PX4's "no log files" answer at once instead of a timeout. Skipped only when MAVSDK cannot be loaded here.
"""

from __future__ import annotations

import asyncio
import os
import time
from pathlib import Path
from typing import Any

import pytest
from support.serve_process import load_mavsdk, serve

pytestmark = pytest.mark.slow  # processes or long flights: not in `make test-fast`

SPEED = 4.0
CALL_TIMEOUT_S = 20.0


@pytest.fixture()
def served(tmp_path: Path):
    """`sitl-emu serve` in tmp_path/work (FTP root work/fs, with a few files); yields (MAVSDK's port, the root)."""
    work = tmp_path / "work"
    root = work / "fs"
    (root / "sub").mkdir(parents=True)
    (root / "hello.txt").write_bytes(b"hello from the emulator\n")
    (root / "big.bin").write_bytes(os.urandom(80_000))
    (tmp_path / "outside.txt").write_bytes(b"secret")
    # SDLOG_MODE 0: no log before arming (PX4 SITL's 1 would start one at boot, and LogFiles would list it)
    with serve(work, tmp_path / "serve.log", SPEED, "--param", "SDLOG_MODE=0") as ports:
        yield ports.api_remote, root


@pytest.mark.timeout(240)
def test_mavsdk_ftp_and_log_files_work_as_against_px4(served, tmp_path):
    mavsdk_asyncio = load_mavsdk()
    port, root = served
    asyncio.run(asyncio.wait_for(_session(mavsdk_asyncio, port, root, tmp_path), timeout=200))
    assert (tmp_path / "outside.txt").read_bytes() == b"secret"


async def _call(awaitable: Any) -> Any:
    return await asyncio.wait_for(awaitable, CALL_TIMEOUT_S)


async def _session(mavsdk_asyncio: Any, port: int, root: Path, tmp_path: Path) -> None:
    from mavsdk.asyncio.plugins.ftp import FtpAsync
    from mavsdk.asyncio.plugins.log_files import LogFilesAsync

    config = mavsdk_asyncio.Configuration.create_with_component_type(mavsdk_asyncio.ComponentType.GROUND_STATION)
    async with mavsdk_asyncio.Mavsdk(config) as mavsdk:
        await _call(mavsdk.add_any_connection(f"udpin://0.0.0.0:{port}"))
        system = await asyncio.wait_for(mavsdk.first_autopilot(timeout_s=20.0), 25.0)
        assert system is not None, "MAVSDK found no autopilot"
        await _check_log_files(LogFilesAsync(system))
        await _check_ftp(FtpAsync(system), root, tmp_path)


async def _check_log_files(log_files: Any) -> None:
    from mavsdk.plugins.log_files import LogFilesError, LogFilesResult

    started = time.monotonic()
    with pytest.raises(LogFilesError) as no_logs:
        await _call(log_files.get_entries())
    assert no_logs.value.result == LogFilesResult.NO_LOGFILES
    assert time.monotonic() - started < 5.0  # answered, not timed out


async def _check_ftp(ftp: Any, root: Path, tmp_path: Path) -> None:
    from mavsdk.plugins.ftp import FilesystemEntry, FtpError, FtpResult

    listed = await _call(ftp.list_directory("/"))
    kinds = {e.name: (e.entry_type, e.size_bytes) for e in listed.entries}
    # the parameter file serve keeps (SDLOG_MODE is set), in the root as in PX4 SITL's
    assert kinds.pop("parameters.params")[0] == FilesystemEntry.EntryType.FILE
    assert kinds == {"etc": (FilesystemEntry.EntryType.DIRECTORY, 0),  # PX4 SITL's ROMFS extras: the metadata
                     "sub": (FilesystemEntry.EntryType.DIRECTORY, 0),
                     "hello.txt": (FilesystemEntry.EntryType.FILE, 24),
                     "big.bin": (FilesystemEntry.EntryType.FILE, 80_000)}
    for use_burst in (True, False):
        local = tmp_path / f"down_{use_burst}"
        local.mkdir()
        async for _ in ftp.download("/big.bin", str(local), use_burst):
            pass
        assert (local / "big.bin").read_bytes() == (root / "big.bin").read_bytes()
    upload = tmp_path / "upload.txt"
    upload.write_bytes(b"uploaded by MAVSDK " * 50)
    async for _ in ftp.upload(str(upload), "/sub"):
        pass
    assert (root / "sub" / "upload.txt").read_bytes() == upload.read_bytes()
    assert await _call(ftp.are_files_identical(str(upload), "/sub/upload.txt"))
    await _call(ftp.create_directory("/made"))
    assert (root / "made").is_dir()
    await _call(ftp.remove_directory("/made"))
    await _call(ftp.rename("/sub/upload.txt", "/renamed.txt"))
    await _call(ftp.remove_file("/renamed.txt"))
    assert sorted(p.name for p in root.iterdir()) == ["big.bin", "hello.txt", "sub"]
    refused = tmp_path / "refused"
    refused.mkdir()
    with pytest.raises(FtpError) as escape:
        async for _ in ftp.download("/../outside.txt", str(refused), False):
            pass
    assert escape.value.result == FtpResult.FILE_PROTECTED
