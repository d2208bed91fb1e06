"""The live view's recording as a viewer receives it (issue 25): no empty sticks panel while no sticks come (an
OFFBOARD flight on serve's side), the panel with the first sticks; and a viewer that connects late gets the frames
logged before it came (the viewer's proxy keeps them). Read back with Rerun's own `rerun rrd print`."""

from __future__ import annotations

import re
import subprocess
import time
from pathlib import Path

import pytest
from support.view_process import require_rerun

from flightview.live import LiveView
from flightview.scene import Frame

STICKS_VIEW = "┆ [plots/sticks]"  # a view whose origin is the sticks' plots, as `rrd print -vvv` shows a blueprint


def printed(path: Path) -> str:
    from flightview.server import rerun_program

    return subprocess.run([rerun_program(), "rrd", "print", "-vvv", str(path)], capture_output=True, text=True,
                          timeout=60, check=True).stdout


def fly(live: LiveView, frames: int, sticks_from: int | None = None) -> None:
    for i in range(frames):
        sticks = (0.1, 0.0, 0.5, 0.0) if sticks_from is not None and i >= sticks_from else None
        live.log("v", Frame(time_s=i * 0.1, pos_ned_m=(0.1 * i, 0.0, -2.0), sticks=sticks, mode="OFFBOARD"))
        live.end_frame()


def test_no_sticks_panel_without_sticks_and_one_with_the_first_sticks(tmp_path: Path) -> None:
    require_rerun()
    offboard, manual = tmp_path / "offboard.rrd", tmp_path / "manual.rrd"
    live = LiveView("t", ["v"], None, offboard)
    fly(live, 20)
    live.close()
    text = printed(offboard)
    assert "┆ [plots/north]" in text and STICKS_VIEW not in text  # the layout, without an empty sticks panel

    live = LiveView("t", ["v"], None, manual)
    fly(live, 20, sticks_from=10)
    live.close()
    text = printed(manual)
    assert text.count(STICKS_VIEW) == 1  # the layout sent again once, now with the panel
    assert "make_active: true" in text  # and shown at once


def rows_of(text: str, entity: str) -> int:
    """The temporal rows `rrd print -vvv` shows for `entity` (its one static row, the series' names, left out)."""
    counts = [int(m.group(1)) for m in re.finditer(rf"with (\d+) rows \([^)]*\) - {re.escape(entity)} - ", text)]
    return sum(counts) - 1 if counts else 0


def viewer(url: str, path: Path) -> subprocess.Popen[bytes]:
    """Rerun's own viewer without a window: it connects to the page's proxy as the page does and saves what it
    gets (it also listens for loggers itself: on a free loopback port here)."""
    from flightview.server import rerun_program

    return subprocess.Popen([rerun_program(), url, "--save", str(path), "--bind", "127.0.0.1", "--port", "0"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


@pytest.mark.slow
def test_a_viewer_gets_every_frame_whether_it_connects_before_the_flight_or_after_it(tmp_path: Path) -> None:
    """The page may be loaded before the first frame or long after: the proxy serve --view starts keeps what was
    logged (up to its memory limit) and hands it to each viewer that connects."""
    require_rerun()
    from flightview.server import start_server

    server = start_server()
    early_path, late_path = tmp_path / "early.rrd", tmp_path / "late.rrd"
    live = LiveView("t", ["v"], server, None)
    try:
        early = viewer(server.grpc_url, early_path)
        time.sleep(2.0)  # connected before any frame
        fly(live, 200)
        live.rec.flush()
        late = viewer(server.grpc_url, late_path)
        time.sleep(4.0)
        for proc in (early, late):
            proc.terminate()
            proc.wait(10)
    finally:
        live.close()
        server.stop()
    for path in (early_path, late_path):
        text = printed(path)
        assert rows_of(text, "/plots/north/v") == 200, path.name
        assert "┆ [plots/north]" in text  # the layout too
