"""The viewer's small parts: a browser only where a display exists; the page's URL points at the loopback proxy."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from typing import Any

import pytest

from flightview import server


def test_no_browser_without_a_display(monkeypatch: pytest.MonkeyPatch) -> None:
    opened: list[str] = []
    monkeypatch.setattr(server.webbrowser, "open", lambda url, new=0: opened.append(url) or True)
    monkeypatch.setattr(server.sys, "platform", "linux")
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    assert server.open_browser("http://127.0.0.1:1/") is False
    monkeypatch.setenv("DISPLAY", ":0")
    assert server.open_browser("http://127.0.0.1:1/") is True
    assert opened == ["http://127.0.0.1:1/"]


def test_the_page_reads_from_the_loopback_proxy() -> None:
    proc: Any = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    view = server.ViewerServer(proc, 8000, 9000, open(__file__, "rb"))  # noqa: SIM115 (stop() closes it)
    assert view.grpc_url == "rerun+http://127.0.0.1:9000/proxy"
    assert view.url == "http://127.0.0.1:8000/?url=rerun%2Bhttp%3A%2F%2F127.0.0.1%3A9000%2Fproxy"
    view.stop()
    assert view.errors.closed


def test_a_privileged_port_is_not_called_in_use(monkeypatch: pytest.MonkeyPatch) -> None:
    """A non-root user's --view-port 80 fails with EACCES: say so, not "in use"."""

    class Refusing:
        def __init__(self, *args: Any) -> None:
            pass

        def __enter__(self) -> Refusing:
            return self

        def __exit__(self, *exc: Any) -> None:
            pass

        def bind(self, address: Any) -> None:
            raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(server.socket, "socket", Refusing)
    with pytest.raises(server.ViewError) as info:
        server.check_port_free(80)
    assert "needs administrator rights" in str(info.value) and "in use" not in str(info.value)


CHILD_WITH_GRANDCHILD = ("import subprocess, sys, time\n"
                         "g = subprocess.Popen([sys.executable, '-c', 'import time; time.sleep(60)'])\n"
                         "print(g.pid, flush=True)\n"
                         "time.sleep(60)\n")


def _viewer_like() -> tuple[subprocess.Popen[bytes], int]:
    process = subprocess.Popen([sys.executable, "-c", CHILD_WITH_GRANDCHILD], stdout=subprocess.PIPE,
                               start_new_session=True)
    assert process.stdout is not None
    return process, int(process.stdout.readline())


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    with open(f"/proc/{pid}/stat") as stat:  # a zombie (not yet reaped by init) counts as ended
        return stat.read().split(") ")[1][0] != "Z"


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the POSIX side, checked through /proc (CI is Linux)")
def test_stopping_the_viewer_ends_its_whole_session_where_there_are_process_groups() -> None:
    process, grandchild = _viewer_like()
    server.terminate_session(process)
    assert process.wait(10) == -15
    for _ in range(200):
        if not _alive(grandchild):
            break
        time.sleep(0.02)
    assert not _alive(grandchild)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="simulated on Linux (CI is Linux)")
def test_without_process_groups_the_viewer_alone_is_terminated(monkeypatch: pytest.MonkeyPatch) -> None:
    process, grandchild = _viewer_like()
    monkeypatch.delattr(os, "killpg")  # Windows
    try:
        server.terminate_session(process)
        assert process.wait(10) == -15
    finally:
        os.kill(grandchild, 9)


def test_the_death_signal_is_asked_for_only_where_prctl_exists(monkeypatch: pytest.MonkeyPatch) -> None:
    class NoPrctl:  # macOS's libc
        def __init__(self, *args: Any, **kwargs: Any) -> None:
            pass
    monkeypatch.setattr(server.ctypes, "CDLL", NoPrctl)
    server._die_with_parent()  # nothing raised in the child before exec
