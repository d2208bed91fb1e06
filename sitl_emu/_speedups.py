"""Guard for the opt-in compiled build (`make speedups`, tools/build_speedups.py): a stale or foreign build never runs.

`make speedups` compiles hot modules with mypyc into extension modules next to their sources and records the sha256
of every source it read in _speedups_manifest.json. Python imports an extension module in preference to the .py
beside it, so an edit to the .py would silently do nothing. When sitl_emu is imported, `guard()` checks the build:
if any compiled module's source, any source it depends on, or any built file differs from the manifest (or there is
no manifest), every compiled module is imported from its .py instead (a sys.meta_path finder) and one warning says
to run `make speedups` again. Set SITL_EMU_PURE=1 to use the pure-Python modules on purpose (no warning).

Cheap when nothing is built: one walk over the package's few folders, no file read.
"""

from __future__ import annotations

import hashlib
import importlib.abc
import importlib.machinery
import importlib.util
import json
import logging
import os
import sys
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType

LOG = logging.getLogger("sitl_emu")
MANIFEST_NAME = "_speedups_manifest.json"
PURE_ENV = "SITL_EMU_PURE"
_PACKAGE_DIR = Path(__file__).resolve().parent


@dataclass
class Plan:
    """What to do at import: the modules to load from their .py, and the warning to log (None: silent)."""

    sources: dict[str, str] = field(default_factory=dict)  # module name -> .py path
    warning: str | None = None


class PureSourceFinder(importlib.abc.MetaPathFinder):
    """Finds the listed modules as their .py source, ahead of the extension module beside it."""

    def __init__(self, sources: dict[str, str]) -> None:
        self.sources = dict(sources)

    def find_spec(self, fullname: str, path: object = None, target: ModuleType | None = None,
                  ) -> importlib.machinery.ModuleSpec | None:
        source = self.sources.get(fullname)
        if source is None:
            return None
        return importlib.util.spec_from_file_location(fullname, source)


def built_extensions(package_dir: Path) -> dict[str, Path]:
    """Extension modules under the package that this interpreter would import: relative path -> file."""
    suffixes = tuple(importlib.machinery.EXTENSION_SUFFIXES)
    found: dict[str, Path] = {}
    for folder, dirs, files in os.walk(package_dir):
        dirs[:] = [d for d in dirs if d != "__pycache__"]
        for name in files:
            if name.endswith(suffixes):
                path = Path(folder, name)
                found[path.relative_to(package_dir.parent).as_posix()] = path
    return found


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _module_of(rel_path: str) -> str | None:
    """'sitl_emu/control/rate.cpython-311-x86_64-linux-gnu.so' -> 'sitl_emu.control.rate' (None: not a module)."""
    for suffix in importlib.machinery.EXTENSION_SUFFIXES:
        if rel_path.endswith(suffix):
            return rel_path.removesuffix(suffix).replace("/", ".")
    return None


def _first_difference(manifest: dict, built: dict[str, Path], root: Path) -> str | None:
    """Why the build does not match its manifest ('sitl_emu/physics.py changed'), or None when it does."""
    recorded = {m["so"]: m["so_sha256"] for m in manifest["compiled"].values()}
    recorded |= {lib["so"]: lib["so_sha256"] for lib in manifest["shared_libs"]}
    for rel in sorted(recorded.keys() - built.keys()):
        return f"{rel} is missing"
    for rel in sorted(built):
        if rel not in recorded:
            return f"{rel} was not built by `make speedups`"
        if _sha256(built[rel]) != recorded[rel]:
            return f"{rel} differs from the build"
    sources = {m["py"]: m["py_sha256"] for m in manifest["compiled"].values()} | manifest["depends"]
    for rel, digest in sorted(sources.items()):
        path = root / rel
        if not path.is_file() or _sha256(path) != digest:
            return f"{rel} changed since the build"
    return None


def plan(package_dir: Path, environ: Mapping[str, str]) -> Plan:
    """Decide which compiled modules to bypass. Pure: reads files, changes nothing."""
    built = built_extensions(package_dir)
    if not built:
        return Plan()
    root = package_dir.parent
    sources = {}
    for rel in built:
        name = _module_of(rel)
        py = root / f"{(name or '').replace('.', '/')}.py"
        if name is not None and py.is_file():
            sources[name] = str(py)
    if environ.get(PURE_ENV, "") not in ("", "0"):
        return Plan(sources)
    try:
        manifest = json.loads((package_dir / MANIFEST_NAME).read_text())
        reason = _first_difference(manifest, built, root)
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        reason = f"{MANIFEST_NAME} is missing or unreadable"
    if reason is None:
        return Plan()
    return Plan(sources, f"sitl_emu: the compiled speedups are stale ({reason}); using the pure-Python modules "
                         "instead. Run `make speedups` again (or `make clean-speedups`).")


def guard(package_dir: Path = _PACKAGE_DIR) -> Plan:
    """Called by sitl_emu/__init__.py: install the fallback finder and log the warning if the plan says so."""
    decided = plan(package_dir, os.environ)
    if decided.sources:
        sys.meta_path.insert(0, PureSourceFinder(decided.sources))
    if decided.warning:
        LOG.warning(decided.warning)
    return decided


def compiled_modules() -> list[str]:
    """The sitl_emu modules imported so far that run compiled (empty: pure Python). For benchmarks and reports."""
    suffixes = tuple(importlib.machinery.EXTENSION_SUFFIXES)
    return sorted(name for name, mod in list(sys.modules.items())
                  if name.startswith("sitl_emu.") and not name.endswith("__mypyc")
                  and str(getattr(mod, "__file__", "") or "").endswith(suffixes))


def describe() -> str:
    """One line for a benchmark report: 'pure Python' or 'compiled (mypyc): N modules'."""
    names = compiled_modules()
    return f"compiled (mypyc): {len(names)} modules" if names else "pure Python"


def build_line(package_dir: Path = _PACKAGE_DIR, environ: Mapping[str, str] = os.environ) -> str:
    """One line for start-up (serve, campaign, bench): does the vehicle core run compiled, and if not, why not."""
    names = [name for name in map(_module_of, built_extensions(package_dir))
             if name is not None and not name.endswith("__mypyc")]
    if not names:
        return ("core: pure Python (`make speedups` in a checkout, or SITL_EMU_COMPILE=1 at pip install, compiles "
                "it: README, \"The compiled build\")")
    decided = plan(package_dir, environ)
    count = f"{len(names)} module{'' if len(names) == 1 else 's'}"
    if not decided.sources:
        return f"core: compiled (mypyc), {count}"
    why = f"{PURE_ENV} is set" if decided.warning is None else "the compiled build is stale"
    return f"core: pure Python ({why}; {count} compiled, not used)"
