"""The example joystick scripts of joyfly's source repository (examples/), named in hints so that they work from any
folder: by their absolute path when joyfly runs from a clone (an editable install, or PYTHONPATH), else as the
repository's files (a wheel carries no examples).
"""

from __future__ import annotations

from pathlib import Path

EXAMPLES_DIR = Path(__file__).resolve().parents[2] / "examples"  # joyfly/sticks/ -> the clone's root
OFFBOARD_SCRIPT = "joystick_script.txt"  # OFFBOARD: joyfly takes off by itself
POSITION_SCRIPT = "joystick_script_position.txt"  # --control position/altitude: the throttle takes off


def example_script(name: str = OFFBOARD_SCRIPT) -> str:
    """The example script `name`: its absolute path in this clone, or where it is in joyfly's source repository."""
    path = EXAMPLES_DIR / name
    return str(path) if path.is_file() else f"examples/{name} in joyfly's source repository"


def virtual_joystick_hint(name: str = OFFBOARD_SCRIPT) -> str:
    """How to fly with no joystick, for an error's last words: `--joy script:<the example's absolute path>`."""
    path = EXAMPLES_DIR / name
    if path.is_file():
        return f"--joy script:{path}"
    return f"--joy script:FILE (such as examples/{name} in joyfly's source repository)"


def missing_example(path: str) -> str | None:
    """`path` names an example (examples/joystick_script.txt) from outside the clone: the example's absolute path."""
    given = Path(path)
    here = EXAMPLES_DIR / given.name
    if given.parent.name == EXAMPLES_DIR.name and not given.is_absolute() and here.is_file():
        return str(here)
    return None
