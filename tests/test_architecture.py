"""The arrows ARCHITECTURE.md forbids: the vehicle core knows no MAVLink, no runtime, no clock; joyfly's stick side
knows nothing of the link or the session; joyfly imports sitl_emu only in its demo; px4common, what both programs
share, is a leaf that only they import."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest
from support import REPO_ROOT


def imports_of(path: Path) -> set[str]:
    """The modules a source imports; `from a import b` counts a and a.b (b may be a module)."""
    tree = ast.parse(path.read_text())
    found = {n.module or "" for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)}
    found |= {f"{n.module}.{a.name}" for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) for a in n.names}
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


# Inside the vehicle core the arrows point one way: vehicle/ -> flight_tasks/ -> commander/ -> navigator/ ->
# motion_planning/ (ARCHITECTURE.md); each folder's __init__.py says the same.
BELOW: dict[str, tuple[str, ...]] = {
    "sitl_emu/motion_planning": ("sitl_emu.navigator", "sitl_emu.commander", "sitl_emu.flight_tasks",
                                 "sitl_emu.vehicle"),
    "sitl_emu/navigator": ("sitl_emu.commander", "sitl_emu.flight_tasks", "sitl_emu.vehicle"),
    "sitl_emu/commander": ("sitl_emu.flight_tasks", "sitl_emu.vehicle"),
    "sitl_emu/flight_tasks": ("sitl_emu.vehicle",),
}


@pytest.mark.parametrize("path", [p for folder in BELOW for p in sources(folder)],
                         ids=lambda p: str(p.relative_to(REPO_ROOT)))
def test_the_vehicle_cores_folders_import_only_downwards(path: Path) -> None:
    folder = str(path.parent.relative_to(REPO_ROOT))
    bad = {m for m in imports_of(path) if any(m == f or m.startswith(f + ".") for f in BELOW[folder])}
    assert not bad, f"{path.name} imports {sorted(bad)}"


@pytest.mark.parametrize("path", sources("joyfly/sticks"), ids=lambda p: p.name)
def test_the_stick_side_knows_neither_the_link_nor_the_session(path: Path) -> None:
    assert not {m for m in imports_of(path) if m.startswith(("joyfly.link", "joyfly.session"))}


@pytest.mark.parametrize("path", sources("joyfly"), ids=lambda p: str(p.relative_to(REPO_ROOT)))
def test_joyfly_speaks_only_mavlink_to_sitl_emu_except_in_its_demo(path: Path) -> None:
    if path.name != "demo.py":
        assert not {m for m in imports_of(path) if m.startswith("sitl_emu")}, path.name


@pytest.mark.parametrize("path", sources("px4common"), ids=lambda p: p.name)
def test_the_shared_package_imports_neither_program(path: Path) -> None:
    assert not {m for m in imports_of(path) if m.startswith(("sitl_emu", "joyfly", "flightview"))}, path.name


@pytest.mark.parametrize("path", sources("flightview"), ids=lambda p: p.name)
def test_only_the_two_programs_import_the_shared_package(path: Path) -> None:
    assert not {m for m in imports_of(path) if m.startswith("px4common")}, path.name


def test_the_shared_package_holds_what_both_programs_use() -> None:
    """A module in px4common that one program alone imports belongs in that program."""
    users: dict[str, set[str]] = {}
    for program in ("sitl_emu", "joyfly"):
        for path in sources(program):
            for module in imports_of(path):
                if module.startswith("px4common."):
                    users.setdefault(".".join(module.split(".")[:2]), set()).add(program)
    shared = {f"px4common.{p.stem}" for p in sources("px4common") if p.stem != "__init__"}
    assert {m: u for m, u in users.items() if u != {"sitl_emu", "joyfly"}} == {}
    assert shared == set(users), f"imported by neither program: {sorted(shared - set(users))}"
