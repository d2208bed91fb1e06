"""The test suite mirrors the packages: tests/sitl_emu/{core,mavlink,runtime,testing,log,...}/, tests/joyfly/,
tests/cli/ (both command lines), with shared fakes and helpers in tests/support/ (on sys.path via pyproject's pytest
settings) and the fixtures several folders use here.

The folders whose modules `make speedups` compiles (COMPILED_FOLDERS: the vehicle core, Sim, the link, the runners,
the flight log, the disturbances) get the `compiled` marker here, and `make compiled-check` runs `pytest -m compiled`
against the mypyc build.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from support.mavsdk_waits import MAVSDK_SPEED
from support.serve_process import serve

COMPILED_FOLDERS = tuple(Path(__file__).parent / "sitl_emu" / name
                         for name in ("core", "testing", "mavlink", "runtime", "log", "disturbance"))


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", "compiled: a test run again against the compiled build (make compiled-check)")


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        if any(folder in item.path.parents for folder in COMPILED_FOLDERS):
            item.add_marker(pytest.mark.compiled)


@pytest.fixture()
def mavsdk_port(tmp_path: Path) -> Iterator[int]:
    """`sitl-emu serve --speed MAVSDK_SPEED` on free ports, in tmp_path (the parameters it sets are saved there, not in
    the repository); yields the UDP port MAVSDK must listen on (the API link's remote)."""
    with serve(tmp_path, tmp_path / "serve.log", MAVSDK_SPEED) as ports:
        yield ports.api_remote
