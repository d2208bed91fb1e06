"""The test suite mirrors the packages: tests/sitl_emu/{core,mavlink,runtime,testing}/, tests/joyfly/, tests/cli/
(both command lines), with shared fakes and helpers in tests/support/ (on sys.path via pyproject's pytest settings).

tests/sitl_emu/core/ holds the tests of the vehicle core (physics, controllers, flight stack, vehicle step, fidelity
against PX4's traces, determinism), tests/sitl_emu/testing/ those of Sim, and tests/sitl_emu/mavlink/ those of the
link, which hands what it decodes from the wire to the compiled types and enums: all three get the `compiled` marker
here, and `make compiled-check` runs `pytest -m compiled` against the mypyc build.
"""

from __future__ import annotations

from pathlib import Path

import pytest

COMPILED_FOLDERS = tuple(Path(__file__).parent / "sitl_emu" / name
                         for name in ("core", "testing", "mavlink", "runtime", "log", "disturbance"))


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", "compiled: a test run again against the compiled build (make compiled-check)")


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        if any(folder in item.path.parents for folder in COMPILED_FOLDERS):
            item.add_marker(pytest.mark.compiled)
