"""flightview knows neither package that feeds it, and imports Rerun only when a view starts (so --view without the
extra is one sentence, and nothing else pays for the import)."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest
from support import REPO_ROOT

SOURCES = sorted((REPO_ROOT / "flightview").glob("*.py"))


def module_imports(path: Path) -> tuple[set[str], set[str]]:
    """(imports at module level, imports anywhere) of a source file."""
    tree = ast.parse(path.read_text())
    top: set[str] = set()
    every: set[str] = set()
    for node in ast.walk(tree):
        names = ([alias.name for alias in node.names] if isinstance(node, ast.Import)
                 else [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
        every.update(names)
        if node in tree.body:
            top.update(names)
    return top, every


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: p.name)
def test_flightview_imports_neither_sitl_emu_nor_joyfly_and_rerun_only_lazily(path: Path) -> None:
    top, every = module_imports(path)
    assert not {m for m in every if m.startswith(("sitl_emu", "joyfly"))}
    assert not {m for m in top if m.startswith("rerun")}


def test_there_are_sources() -> None:
    assert len(SOURCES) >= 5
