"""The js reader behind its platform seam (joyfly/sticks/js/seam.py): where it cannot be imported (Windows has no
fcntl), joyfly still imports, SDL and the virtual joysticks still work, and a js path is one sentence; where it can,
everything goes to it as before."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from support import REPO_ROOT

from joyfly.sticks.js.events import JoystickError
from joyfly.sticks.js.seam import JS_MODULE, JsUnavailable, js_reader, js_reader_or_none, open_js
from joyfly.sticks.virtual import ScriptSource

MISSING = "joyfly.sticks.no_js_api_here"


class Clock:
    def now(self) -> float:
        return 0.0

    def sleep(self, seconds: float) -> None:
        pass


def test_with_the_js_api_everything_goes_to_the_js_reader(tmp_path: Path) -> None:
    assert js_reader(JS_MODULE).__name__ == JS_MODULE
    with pytest.raises(JoystickError, match="is a directory"):
        open_js(str(tmp_path), Clock(), "/dev/input")


def test_without_it_the_portable_kinds_open_and_a_js_path_is_one_sentence(tmp_path: Path) -> None:
    script = tmp_path / "s.txt"
    script.write_text("0 forward=0.5\n")
    assert isinstance(open_js(f"script:{script}", Clock(), "/dev/input", MISSING), ScriptSource)
    assert js_reader_or_none(MISSING) is None
    with pytest.raises(JsUnavailable) as err:
        open_js("/dev/input/js0", Clock(), "/dev/input", MISSING)
    assert str(err.value).startswith("This system has no Linux joystick (js) API") and "--joy sdl" in str(err.value)


BLOCK = "import sys\nfor m in ('fcntl', 'termios', 'tty', 'pty'):\n    sys.modules[m] = None\n"


@pytest.mark.slow
def test_joyfly_runs_where_there_is_no_fcntl(tmp_path: Path) -> None:
    script = tmp_path / "s.txt"
    script.write_text("0 forward=0.5\n0.1 end\n")
    code = BLOCK + "from joyfly.cli import main\nmain(sys.argv[1:], prog_name='joyfly')\n"

    def joyfly(*args: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run([sys.executable, "-c", code, *args], cwd=REPO_ROOT, capture_output=True, text=True,
                              timeout=60)

    test = joyfly("joystick", "test", "--joy", f"script:{script}")
    assert test.returncode == 0 and "forward=+0.50" in test.stdout, test.stderr
    fly = joyfly("fly", "--joy", "/dev/input/js0")
    assert fly.returncode == 2 and fly.stderr.startswith("joyfly: This system has no Linux joystick (js) API"), \
        fly.stderr
    listed = joyfly("joystick", "list")
    assert "Traceback" not in listed.stderr and listed.returncode == 0, listed.stderr
    assert "No joystick found" in listed.stdout, listed.stdout
