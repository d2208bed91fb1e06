"""The test suite mirrors the packages: tests/sitl_emu/{vehicle,commander,navigator,flight_tasks,mavlink,...}/ as
sitl_emu's folders, tests/joyfly/, tests/px4common/, tests/cli/ (both command lines), with shared fakes and helpers in
tests/support/ (on sys.path via pyproject's pytest settings) and the fixtures several folders use here.

The folders whose modules `make speedups` compiles (COMPILED_FOLDERS: the vehicle core, Sim, the link, the runners,
the flight log, the disturbances; COMPILED_FILES: the kernel's) get the `compiled` marker here, and
`make compiled-check` runs `pytest -m compiled` against the mypyc build.

Two tiers: `slow` marks the tests that start processes (serve, joyfly, MAVSDK, MAVProxy, a browser, an SDL pilot)
or fly long end-to-end flights; `make test-fast` runs the others (`pytest -m "not slow"`), `make test` all of them,
on two xdist workers.

Every test must leave the checkout as it found it (servers run in tmp_path): `_leaves_no_files_in_the_checkout` fails
the one that does not.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from support import REPO_ROOT
from support.checkout_guard import checkout_files, left_behind, top_level_files
from support.mavsdk_waits import MAVSDK_SPEED
from support.serve_process import serve

_SITL_EMU_TESTS = Path(__file__).parent / "sitl_emu"
COMPILED_FOLDERS = tuple(_SITL_EMU_TESTS / name for name in (
    "vehicle", "commander", "navigator", "flight_tasks", "motion_planning", "control",  # the vehicle core
    "testing", "mavlink", "runtime", "log", "disturbance"))
COMPILED_FILES = (_SITL_EMU_TESTS / "test_geo.py", _SITL_EMU_TESTS / "test_physics.py")  # the kernel's


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", "compiled: a test run again against the compiled build (make compiled-check)")
    config.addinivalue_line("markers", "slow: starts processes or flies long end-to-end: not in `make test-fast`")


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        if item.path in COMPILED_FILES or any(folder in item.path.parents for folder in COMPILED_FOLDERS):
            item.add_marker(pytest.mark.compiled)


@pytest.fixture()
def mavsdk_port(tmp_path: Path) -> Iterator[int]:
    """`sitl-emu serve --speed MAVSDK_SPEED` on free ports, in tmp_path (the parameters it sets are saved there, not in
    the repository); yields the UDP port MAVSDK must listen on (the API link's remote)."""
    with serve(tmp_path, tmp_path / "serve.log", MAVSDK_SPEED) as ports:
        yield ports.api_remote


@pytest.fixture(autouse=True)
def _leaves_no_files_in_the_checkout() -> Iterator[None]:
    """Fails the test after which the checkout's top folder holds new files (where `serve` started without cwd writes
    log/ and parameters.params). With xdist workers, the writer may be a test running at the same time on the other
    worker: the message says so."""
    before = top_level_files(REPO_ROOT)
    yield
    _fail_if_left(left_behind(before, top_level_files(REPO_ROOT)), "this test")


@pytest.fixture(autouse=True, scope="module")
def _module_leaves_no_files_in_the_checkout() -> Iterator[None]:
    """The same for the whole tree, once per module (a walk of about 2 ms)."""
    before = checkout_files(REPO_ROOT)
    yield
    _fail_if_left(left_behind(before, checkout_files(REPO_ROOT)), "a test of this module")


def _fail_if_left(left: list[str], who: str) -> None:
    if left:
        pytest.fail(f"{who} (or one running beside it on another xdist worker) left {', '.join(left)} in the "
                    f"checkout {REPO_ROOT}: run servers with cwd=tmp_path and write files under tmp_path",
                    pytrace=False)
