"""How to install an optional extra (plot, ray), said as README and the view's texts say it (flightview/server.py
does the same for the view extra: flightview imports no program's code).

README installs from the clone with `.venv/bin/pip install -e '.[EXTRA]'`. A help text says the same, `pip install -e
'.[EXTRA]' in the joyfly clone`; an error gives the command to paste: this Python's pip with the clone's path, so it
works from any folder (or, where sitl-emu does not run from a clone, the extra's packages alone).
"""

from __future__ import annotations

import shlex
import sys
from pathlib import Path

SOURCE_ROOT = Path(__file__).resolve().parents[2]  # the clone, when joyfly runs from one (pip install -e)


def in_clone(extra: str) -> str:
    """For help texts: "pip install -e '.[plot]' in the joyfly clone"."""
    return f"pip install -e '.[{extra}]' in the joyfly clone"


def install_command(extra: str, packages: str) -> str:
    """For errors: the command that installs `extra` into the Python running now, runnable from anywhere: `pip
    install -e 'CLONE[extra]'` from a clone, else `packages` (the extra's requirements, quoted for a shell)."""
    target = f"-e {shlex.quote(f'{SOURCE_ROOT}[{extra}]')}" if (SOURCE_ROOT / "pyproject.toml").exists() else packages
    return f"{shlex.quote(sys.executable)} -m pip install {target}"
