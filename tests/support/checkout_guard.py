"""The files in the checkout, so that tests/conftest.py can fail a test that leaves new ones there (`sitl-emu serve`
started without cwd=tmp_path writes log/ and parameters.params into the working directory; .gitignore hides them from
`git status`, so the snapshot walks the tree itself). Caches and build output are skipped. Around every test only the
checkout's top folder is listed (microseconds: that is where a server started without cwd writes); around every
module the whole tree is walked (about 2 ms)."""

from __future__ import annotations

import os
from pathlib import Path

# Folders that tools write to during a run: the interpreter's and the linters' caches, the venv, the build tree
# (`make compiled-check` copies the checkout into build/compiled-check and builds there).
SKIPPED_FOLDERS = frozenset({".git", ".venv", "build", "dist", "__pycache__", ".pytest_cache", ".mypy_cache",
                             ".ruff_cache", ".hypothesis"})


def checkout_files(root: Path) -> frozenset[str]:
    """Every file and folder under `root` (relative paths), outside SKIPPED_FOLDERS and *.egg-info."""
    found: set[str] = set()
    folders = [str(root)]
    prefix = len(str(root)) + 1
    while folders:
        with os.scandir(folders.pop()) as entries:
            for entry in entries:
                if entry.is_dir(follow_symlinks=False):
                    if entry.name in SKIPPED_FOLDERS or entry.name.endswith(".egg-info"):
                        continue
                    folders.append(entry.path)
                found.add(entry.path[prefix:])
    return frozenset(found)


def top_level_files(root: Path) -> frozenset[str]:
    """The names in `root` itself, outside SKIPPED_FOLDERS and *.egg-info."""
    return frozenset(name for name in os.listdir(root)
                     if name not in SKIPPED_FOLDERS and not name.endswith(".egg-info"))


def left_behind(before: frozenset[str], after: frozenset[str]) -> list[str]:
    """The new paths, a new folder standing for everything under it (log/ rather than each log file in it)."""
    new = after - before
    return sorted(path for path in new if os.path.dirname(path) not in new)
