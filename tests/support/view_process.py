"""A command started with --view as a separate process: its page's URL, the sockets its viewer listens on."""

from __future__ import annotations

import os
import queue
import re
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any, NamedTuple

import pytest

from support import REPO_ROOT
from support.serve_process import stop_process

URL_LINE = re.compile(r"live view: (http://\S+)")


class ViewProcess(NamedTuple):
    proc: subprocess.Popen[str]
    url: str
    output: list[str]  # every line so far (a reader thread appends)


def require_rerun() -> None:
    try:
        import rerun  # noqa: F401
    except ImportError:
        pytest.skip("rerun-sdk is not installed: pip install -e '.[view]' to run the view's tests.")


@contextmanager
def view_process(args: list[str], cwd: Path, timeout_s: float = 60.0) -> Iterator[ViewProcess]:
    """`python -m <args>` with no display (no browser opens), until its `live view: URL` line; stopped after."""
    env = {key: value for key, value in os.environ.items() if key not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env["PYTHONPATH"] = os.pathsep.join([str(REPO_ROOT), os.environ.get("PYTHONPATH", "")])
    proc = subprocess.Popen([sys.executable, "-m", *args], cwd=cwd, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, text=True)
    lines: list[str] = []
    urls: queue.Queue[str] = queue.Queue()
    reader = threading.Thread(target=_read, args=(proc, lines, urls), daemon=True)
    reader.start()
    try:
        try:
            url = urls.get(timeout=timeout_s)
        except queue.Empty:
            pytest.fail(f"no `live view:` line within {timeout_s:g} s; output: {''.join(lines)[-2000:]}")
        if not url:  # its output ended: the command exited first
            pytest.fail(f"the command ended before its `live view:` line; output: {''.join(lines)[-2000:]}")
        yield ViewProcess(proc, url, lines)
    finally:
        stop_process(proc)
        reader.join(5)
        print("--- output ---\n" + "".join(lines)[-3000:])


def _read(proc: subprocess.Popen[str], lines: list[str], urls: queue.Queue[str]) -> None:
    assert proc.stdout is not None
    for line in proc.stdout:
        lines.append(line)
        match = URL_LINE.search(line)
        if match:
            urls.put(match.group(1))
    urls.put("")  # the output ended


def listening_sockets(root_pid: int) -> list[Any]:
    """psutil's TCP listening sockets of `root_pid` and all its descendants (the viewer is a child process)."""
    import psutil

    pids = {root_pid} | {child.pid for child in psutil.Process(root_pid).children(recursive=True)}
    return [c for c in psutil.net_connections(kind="tcp") if c.status == psutil.CONN_LISTEN and c.pid in pids]


def wait_until(predicate: Any, timeout_s: float, step_s: float = 0.2) -> bool:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(step_s)
    return bool(predicate())
