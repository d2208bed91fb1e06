"""The test suite mirrors the packages: tests/sitl_emu/{core,mavlink,runtime,testing}/, tests/joyfly/, tests/cli/
(both command lines), with shared fakes and helpers in tests/support/ (on sys.path via pyproject's pytest settings).

tests/sitl_emu/core/ holds the tests of the vehicle core (physics, controllers, flight stack, vehicle step, fidelity
against PX4's traces, determinism) and tests/sitl_emu/testing/ those of Sim: both get the `core` marker here, and
`make compiled-check` runs `pytest -m core` against the mypyc build.
"""

from __future__ import annotations

from pathlib import Path

import pytest

CORE_FOLDERS = (Path(__file__).parent / "sitl_emu" / "core", Path(__file__).parent / "sitl_emu" / "testing")


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", "core: a test of the vehicle core, run again against the compiled build")


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        if any(folder in item.path.parents for folder in CORE_FOLDERS):
            item.add_marker(pytest.mark.core)
