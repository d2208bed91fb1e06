"""Conformance: MAVProxy (a real ground station from PyPI) on `sitl-emu serve`'s ground-station link (issue 13).

MAVProxy runs as a user runs it, with its console on a pipe: it waits for the vehicle's heartbeat, `param fetch`
downloads every parameter, `param set MPC_XY_CRUISE 7` changes one, and `wp list` asks for the mission (none yet).
The test reads MAVProxy's console lines and the files both programs write: MAVProxy's mav.parm (every parameter it
received) and serve's parameters.params (the value the vehicle keeps). Every wait has a timeout; nothing sleeps.

MAVProxy loads only the modules a test uses (its default list also starts fence, rally, terrain and ADS-B work that
has nothing to do with these tests). A second test tries the README's MAVProxy recipes and warnings (issue 25). The
tests skip only when MAVProxy is not installed.
"""

from __future__ import annotations

import importlib.util
import os
import queue
import re
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from support.serve_process import serve, stop_process

from sitl_emu.params import default_registry

pytestmark = pytest.mark.slow  # processes or long flights: not in `make test-fast`

WAIT_S = 30.0  # the longest any single step may take (wall clock)
# ...but the download of all 994 parameters: they come as one burst (PX4's 20 per loop), and a MAVProxy starved of CPU
# on a busy machine can lose part of it from its socket's buffer, and then asks for the missing ones 10 at a time
FETCH_WAIT_S = 120.0


@pytest.fixture()
def gcs_port(tmp_path: Path) -> Iterator[int]:
    """`sitl-emu serve` in tmp_path/serve on free ports; yields the port its ground-station link sends to."""
    workdir = tmp_path / "serve"
    workdir.mkdir()
    with serve(workdir, workdir / "serve.log", 2.0) as ports:
        yield ports.gcs_remote


class MavProxy:
    """MAVProxy with its console on pipes: `send` a command line, `expect` a console line matching a pattern."""

    def __init__(self, port: int, workdir: Path, modules: str = "param,wp") -> None:
        workdir.mkdir()
        args = [sys.executable, "-m", "MAVProxy.mavproxy", "--master", f"udpin:127.0.0.1:{port}",
                "--target-system", "1", "--default-modules", modules]
        # HOME in the test's directory: no user's .mavinit.scr or MAVProxy settings are read
        self.proc = subprocess.Popen(args, cwd=workdir, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=subprocess.STDOUT, text=True, bufsize=1,
                                     env={**os.environ, "HOME": str(workdir)})
        self.lines: queue.Queue[str] = queue.Queue()
        self.seen: list[str] = []
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            self.lines.put(line.rstrip("\n"))

    def send(self, command: str) -> None:
        assert self.proc.stdin is not None
        self.proc.stdin.write(command + "\n")
        self.proc.stdin.flush()

    def expect(self, pattern: str, timeout_s: float = WAIT_S) -> re.Match[str]:
        """The first new console line matching `pattern` (a regular expression searched in the line)."""
        deadline = time.monotonic() + timeout_s
        while (left := deadline - time.monotonic()) > 0:
            try:
                line = self.lines.get(timeout=left)
            except queue.Empty:
                break
            self.seen.append(line)
            found = re.search(pattern, line)
            if found:
                return found
        raise AssertionError(f"MAVProxy printed no line matching {pattern!r} within {timeout_s} s")

    def close(self) -> None:
        if self.proc.stdin is not None and not self.proc.stdin.closed:
            self.proc.stdin.close()  # end of input: MAVProxy's input loop exits
        stop_process(self.proc)


def _wait_for_file_line(path: Path, pattern: str, timeout_s: float = WAIT_S) -> str:
    """The first line of `path` matching `pattern`, polling until it appears (the emulator saves after a change)."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        text = path.read_text() if path.exists() else ""
        found = next((line for line in text.splitlines() if re.search(pattern, line)), None)
        if found is not None:
            return found
        time.sleep(0.05)
    raise AssertionError(f"{path} has no line matching {pattern!r} after {timeout_s} s")


def _shown_value(gcs: MavProxy, name: str, until: float, timeout_s: float = WAIT_S) -> float:
    """What `param show NAME` prints, asked again until it is `until` or the time is up (the last value seen)."""
    deadline = time.monotonic() + timeout_s
    while True:
        gcs.send(f"param show {name}")
        value = float(gcs.expect(rf"{name}\s+(\S+)$").group(1))
        if value == until or time.monotonic() > deadline:
            return value
        time.sleep(0.1)


@pytest.mark.timeout(240)
def test_mavproxy_downloads_every_parameter_sets_one_and_lists_the_mission(gcs_port: int, tmp_path: Path) -> None:
    if importlib.util.find_spec("MAVProxy") is None:
        pytest.skip("MAVProxy is not installed (pip install -e '.[test]' installs it).")
    listed = [d.name for d in default_registry()]  # what sitl-emu lists: PX4's 994 parameters
    gcs = MavProxy(gcs_port, tmp_path / "mavproxy")
    try:
        gcs.expect(r"Detected vehicle 1:1")
        gcs.send("param fetch")
        received = int(gcs.expect(r"Received (\d+) parameters", FETCH_WAIT_S).group(1))
        assert received == len(listed) == 994
        saved = gcs.expect(r"Saved (\d+) parameters to (\S+)")
        names = {line.split()[0] for line in (tmp_path / "mavproxy" / saved.group(2)).read_text().splitlines()
                 if line.strip() and not line.startswith("#")}
        assert names - {"_HASH_CHECK"} == set(listed)

        gcs.send("param set MPC_XY_CRUISE 7")
        kept = _wait_for_file_line(tmp_path / "serve" / "parameters.params", r"\bMPC_XY_CRUISE\b")
        assert float(kept.split()[3]) == 7.0  # the vehicle took the value and keeps it
        assert _shown_value(gcs, "MPC_XY_CRUISE", until=7.0) == 7.0  # and MAVProxy got the vehicle's answer

        gcs.send("wp list")
        assert int(gcs.expect(r"Requesting (\d+) waypoints").group(1)) == 0
        gcs.send("wp status")
        gcs.expect(r"Have 0 of 0 waypoints")
    except AssertionError:
        print("MAVProxy console:\n" + "\n".join(gcs.seen))
        raise
    finally:
        gcs.close()


README = Path(__file__).resolve().parents[2] / "README.md"
HOME_ROW_PLAN = """QGC WPL 110
0\t1\t0\t16\t0\t0\t0\t0\t47.397742\t8.545594\t488.0\t1
1\t0\t3\t22\t0\t0\t0\t0\t47.397742\t8.545594\t6.0\t1
2\t0\t3\t16\t0\t0\t0\t0\t47.397850\t8.545594\t6.0\t1
"""  # as MAVProxy saves a plan: row 0 is ArduPilot's home (frame 0, sea-level altitude), here the vehicle's own


def _readme_mode_recipes() -> list[tuple[str, str]]:
    """(MAVProxy command, mode name) from the README's DO_SET_MODE table."""
    return re.findall(r"^\s*\| `(long DO_SET_MODE [\d ]+)` \| (\w+) \|$", README.read_text(), re.MULTILINE)


@pytest.mark.timeout(180)
def test_the_readmes_mavproxy_recipes_work_and_its_warnings_hold(gcs_port: int, tmp_path: Path) -> None:
    """Issue 25: MAVProxy's `mode X` fails before anything is sent (pymavlink's PX4 mode table holds tuples);
    every DO_SET_MODE line of the README switches the mode; `wp list` ends in PX4's "Mission sync timeout" (MAVProxy
    sends no closing MISSION_ACK); a WPL file's home row is skipped with `wp set 1` and the mission takes off."""
    if importlib.util.find_spec("MAVProxy") is None:
        pytest.skip("MAVProxy is not installed (pip install -e '.[test]' installs it).")
    recipes = _readme_mode_recipes()
    assert [mode for _, mode in recipes] == ["MANUAL", "ALTCTL", "POSCTL", "MISSION", "LOITER", "RTL", "LAND",
                                             "TAKEOFF", "FOLLOWME", "ACRO", "OFFBOARD", "STABILIZED"]
    (tmp_path / "plan.txt").write_text(HOME_ROW_PLAN)
    gcs = MavProxy(gcs_port, tmp_path / "mavproxy", modules="wp,mode,cmdlong,arm")
    try:
        gcs.expect(r"Detected vehicle 1:1")
        gcs.send("mode POSCTL")
        gcs.expect(r"ERROR in command .*required argument is not a float")
        for command, mode in recipes:
            gcs.send(command)
            gcs.expect(rf"Mode {mode}$")
        gcs.send("long DO_SET_MODE 1 4 3")  # Hold, from which the vehicle arms
        gcs.expect(r"Mode LOITER$")

        gcs.send("wp list")
        gcs.expect(r"Requesting 0 waypoints")
        gcs.expect(r"Mission sync timeout", timeout_s=WAIT_S)

        gcs.send(f"wp load {tmp_path / 'plan.txt'}")
        gcs.expect(r"Got MISSION_ACK: TYPE_MISSION: ACCEPTED")
        gcs.send("wp set 1")
        gcs.expect(r"waypoint 1$")
        gcs.send("arm throttle")
        gcs.expect(r"ARMED")
        gcs.send("long DO_SET_MODE 1 4 4")
        gcs.expect(r"Climb to 6\.0 meters above home")  # not held at the home row's ground level
        gcs.expect(r"waypoint 2$")
    except AssertionError:
        print("MAVProxy console:\n" + "\n".join(gcs.seen))
        raise
    finally:
        gcs.close()
