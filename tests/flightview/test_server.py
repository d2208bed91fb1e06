"""The viewer's small parts: a browser only where a display exists; the page's URL points at the loopback proxy."""

from __future__ import annotations

import subprocess
import sys
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
