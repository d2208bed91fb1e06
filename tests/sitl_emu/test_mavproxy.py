"""Conformance: MAVProxy (a real ground station from PyPI) on `sitl-emu serve`'s ground-station link (issue 13).

MAVProxy runs as a user runs it, with its console on a pipe: it waits for the vehicle's heartbeat, `param fetch`
downloads every parameter, `param set MPC_XY_CRUISE 7` changes one, and `wp list` asks for the mission (none yet).
The test reads MAVProxy's console lines and the files both programs write: MAVProxy's mav.parm (every parameter it
received) and serve's parameters.params (the value the vehicle keeps). Every wait has a timeout; nothing sleeps.

MAVProxy loads only its `param` and `wp` modules here (its default list also starts fence, rally, terrain and ADS-B
work that has nothing to do with this test). The test skips only when MAVProxy is not installed.
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

WAIT_S = 30.0  # the longest any single step may take (wall clock)


@pytest.fixture()
def gcs_port(tmp_path: Path) -> Iterator[int]:
    """`sitl-emu serve` in tmp_path/serve on free ports; yields the port its ground-station link sends to."""
    workdir = tmp_path / "serve"
    workdir.mkdir()
    with serve(workdir, workdir / "serve.log", 2.0) as ports:
        yield ports.gcs_remote


class MavProxy:
    """MAVProxy with its console on pipes: `send` a command line, `expect` a console line matching a pattern."""

    def __init__(self, port: int, workdir: Path) -> None:
        workdir.mkdir()
        args = [sys.executable, "-m", "MAVProxy.mavproxy", "--master", f"udpin:127.0.0.1:{port}",
                "--target-system", "1", "--default-modules", "param,wp"]
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


@pytest.mark.timeout(150)
def test_mavproxy_downloads_every_parameter_sets_one_and_lists_the_mission(gcs_port: int, tmp_path: Path) -> None:
    if importlib.util.find_spec("MAVProxy") is None:
        pytest.skip("MAVProxy is not installed (pip install -e '.[test]' installs it).")
    listed = [d.name for d in default_registry()]  # what sitl-emu lists: PX4's 994 parameters
    gcs = MavProxy(gcs_port, tmp_path / "mavproxy")
    try:
        gcs.expect(r"Detected vehicle 1:1")
        gcs.send("param fetch")
        received = int(gcs.expect(r"Received (\d+) parameters").group(1))
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
