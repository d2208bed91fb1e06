"""The arrows ARCHITECTURE.md forbids: the vehicle core knows no MAVLink, no runtime, no clock; joyfly's stick side
knows nothing of the link or the session; joyfly imports sitl_emu only in its demo."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest
from support import REPO_ROOT


def imports_of(path: Path) -> set[str]:
    tree = ast.parse(path.read_text())
    found = {n.module or "" for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)}
    return found | {a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}


def sources(*parts: str) -> list[Path]:
    files: list[Path] = []
    for part in parts:
        path = REPO_ROOT / part
        files += sorted(path.rglob("*.py")) if path.is_dir() else [path]
    return files


CORE = sources("sitl_emu/control", "sitl_emu/vehicle", "sitl_emu/commander", "sitl_emu/navigator",
               "sitl_emu/flight_tasks", "sitl_emu/motion_planning", "sitl_emu/params", "sitl_emu/physics.py",
               "sitl_emu/px4.py", "sitl_emu/types.py", "sitl_emu/geo.py", "sitl_emu/disturbance", "sitl_emu/events")
CORE_MAY_NOT = ("pymavlink", "sitl_emu.mavlink", "sitl_emu.runtime", "sitl_emu.testing", "sitl_emu.cli",
                "sitl_emu.console", "time", "socket", "threading", "random")


@pytest.mark.parametrize("path", CORE, ids=lambda p: str(p.relative_to(REPO_ROOT)))
def test_the_vehicle_core_knows_no_mavlink_runtime_or_clock(path: Path) -> None:
    bad = {m for m in imports_of(path) if any(m == f or m.startswith(f + ".") for f in CORE_MAY_NOT)}
    assert not bad, f"{path.name} imports {sorted(bad)}"


@pytest.mark.parametrize("path", sources("joyfly/sticks"), ids=lambda p: p.name)
def test_the_stick_side_knows_neither_the_link_nor_the_session(path: Path) -> None:
    assert not {m for m in imports_of(path) if m.startswith(("joyfly.link", "joyfly.session"))}


@pytest.mark.parametrize("path", sources("joyfly"), ids=lambda p: str(p.relative_to(REPO_ROOT)))
def test_joyfly_speaks_only_mavlink_to_sitl_emu_except_in_its_demo(path: Path) -> None:
    if path.name != "demo.py":
        assert not {m for m in imports_of(path) if m.startswith("sitl_emu")}, path.name
