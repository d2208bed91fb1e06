"""setuptools' hook for the opt-in compiled build; everything else about the package is in pyproject.toml.

    SITL_EMU_COMPILE=1 pip install .          # from a clone: sitl_emu's hot modules compiled with mypyc
    SITL_EMU_COMPILE=1 python -m build        # a compiled wheel (and an sdist that can build one)

Without SITL_EMU_COMPILE (CI's `pip install -e '.[test]'`, every default install) this is plain setuptools: nothing
is compiled and mypy is not needed. When asked, mypy is added to the build's requirements (setup_requires, which
setuptools' PEP 517 backend hands to pip), and the modules and settings are tools/build_speedups.py's, the same as
`make speedups`: the profile-chosen module set, compilation groups built side by side, MYPYC_OPT_LEVEL, the exact
float flags, and the manifest that sitl_emu/_speedups.py checks at import (a wheel carries its own).
SITL_EMU_COMPILE=sitl_emu/geo.py,... (a comma-separated list) compiles those sources only.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import Any

from setuptools import setup
from setuptools.command.build_ext import build_ext
from setuptools.dist import Distribution

COMPILE_ENV = "SITL_EMU_COMPILE"
MYPY = "mypy>=1.8"  # mypyc, the compiler
HERE = Path(__file__).resolve().parent


def compile_asked(environ: Any = os.environ) -> bool:
    return str(environ.get(COMPILE_ENV, "")).strip() not in ("", "0")


def asked_sources(default: tuple[str, ...], environ: Any = os.environ) -> list[str]:
    """SITL_EMU_COMPILE=1: tools/build_speedups.py's module set; a comma-separated list of sources (for a test or an
    experiment): those."""
    value = str(environ.get(COMPILE_ENV, "")).strip()
    listed = [rel.strip() for rel in value.split(",") if rel.strip().endswith(".py")]
    return [s for s in (listed or default) if not s.endswith("__init__.py")]


def _speedups() -> Any:
    sys.path.insert(0, str(HERE / "tools"))
    import build_speedups

    return build_speedups


class CompiledDistribution(Distribution):
    """A distribution with extension modules (a platform wheel), whose modules build_ext makes when it runs."""

    def has_ext_modules(self) -> bool:
        return True


class MypycBuildExt(build_ext):
    """build_ext that asks mypyc for the C of the speedups modules, compiles it in parallel and writes the manifest
    beside the built modules."""

    def finalize_options(self) -> None:
        speedups = _speedups()
        for var in ("CFLAGS", "CPPFLAGS", "LDFLAGS"):
            os.environ.pop(var, None)  # keep -march=native / -ffast-math out (tools/build_speedups.py)
        self.sources = asked_sources(speedups.DEFAULT_MODULES)
        self.jobs = speedups.build_jobs()
        self.distribution.ext_modules = speedups.extensions(self.sources, speedups.group_count(self.jobs),
                                                            speedups.opt_level())
        super().finalize_options()
        self.parallel = self.parallel or self.jobs

    def run(self) -> None:
        super().run()
        speedups = _speedups()
        out = HERE if self.inplace else Path(self.build_lib)
        speedups.write_manifest(self.sources, out)


if compile_asked():
    setup(distclass=CompiledDistribution, cmdclass={"build_ext": MypycBuildExt}, setup_requires=[MYPY])
else:
    setup()
