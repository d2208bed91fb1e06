"""Rerun's web viewer on loopback only: the bundled `rerun` program, started with `--bind 127.0.0.1`.

The SDK's own rr.serve_grpc() and rr.serve_web_viewer() listen on every address (0.0.0.0) and take no bind address
(rerun-sdk 0.41), so the view runs Rerun's command-line viewer from the installed package as a child process,
`rerun --serve-web --bind 127.0.0.1 --port GRPC --web-viewer-port WEB`: it serves the web viewer (HTML, JS, Wasm,
no internet) and a gRPC proxy that the logging side connects to; the browser page reads from that proxy. Both ports
are picked free on 127.0.0.1 unless --view-port gives the web page's and --view-grpc-port the proxy's.
"""

from __future__ import annotations

import contextlib
import ctypes
import importlib.util
import os
import shlex
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import urllib.parse
import webbrowser
from dataclasses import dataclass
from pathlib import Path
from typing import IO

LOOPBACK = "127.0.0.1"
PR_SET_PDEATHSIG = 1  # linux/prctl.h
START_TIMEOUT_S = 20.0  # the viewer program starts in well under a second; a busy 2-core machine may take longer
SOURCE_ROOT = Path(__file__).resolve().parent.parent  # the clone, when joyfly runs from one (pip install -e)
INSTALL_COMMAND = "pip install -e '.[view]'"  # the view extra, from the clone (README, -h)


def install_hint() -> str:
    """How to install the view extra into the Python running now, as one command that works from anywhere: README's
    `pip install -e '.[view]'` with this Python and this clone's path (Rerun's SDK alone where there is no clone)."""
    target = f"-e {shlex.quote(f'{SOURCE_ROOT}[view]')}" if (SOURCE_ROOT / "pyproject.toml").exists() else \
        "'rerun-sdk>=0.41'"
    return f"{shlex.quote(sys.executable)} -m pip install {target}"


def missing_extra() -> str:
    return f"--view needs the Rerun viewer, which is not installed: {install_hint()}"


class ViewError(Exception):
    """The view cannot start; the message is one sentence saying why and what to do."""


def import_rerun() -> object:
    """The rerun module, or ViewError with the sentence telling how to install it."""
    try:
        import rerun
    except ImportError:
        raise ViewError(missing_extra()) from None
    return rerun


def free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.bind((LOOPBACK, 0))
        return int(sock.getsockname()[1])


def check_port_free(port: int, option: str = "--view-port") -> None:
    """ViewError in one sentence if `port` cannot be listened on at 127.0.0.1."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        try:
            sock.bind((LOOPBACK, port))
        except PermissionError:
            raise ViewError(f"Port {port} on {LOOPBACK} needs administrator rights (ports below 1024 do): pick one "
                            f"above 1023 with {option} or leave it out to use a free one.") from None
        except OSError as err:
            raise ViewError(f"Port {port} on {LOOPBACK} is in use ({err.strerror}): pick another with {option} or "
                            "leave it out to use a free one.") from None


def check_ports(web_port: int | None, grpc_port: int | None) -> None:
    """ViewError in one sentence if the ports given are one port or cannot be listened on."""
    if web_port and web_port == grpc_port:
        raise ViewError(f"--view-port and --view-grpc-port are both {web_port}: the page and its data stream need "
                        "a port each.")
    if web_port:
        check_port_free(web_port, "--view-port")
    if grpc_port:
        check_port_free(grpc_port, "--view-grpc-port")


def rerun_program() -> str:
    """The viewer program installed with rerun-sdk (the rerun_cli package's binary itself: the `rerun` script on PATH
    is a Python wrapper whose child would outlive a stopped wrapper)."""
    spec = importlib.util.find_spec("rerun_cli")
    if spec is not None and spec.origin is not None:
        folder = Path(spec.origin).parent
        for candidate in (folder / "Rerun.app" / "Contents" / "MacOS" / "Rerun", folder / "rerun",
                          folder / "rerun.exe"):
            if candidate.exists():
                return str(candidate)
    found = shutil.which("rerun")
    if found is None:
        raise ViewError(missing_extra())
    return found


def _die_with_parent() -> None:
    """In the child, before exec (Linux): get SIGTERM when the process that started the viewer dies, even by
    SIGKILL, so no viewer is left listening."""
    with contextlib.suppress(Exception):
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(PR_SET_PDEATHSIG, signal.SIGTERM)


def terminate_session(process: subprocess.Popen[bytes]) -> None:
    """SIGTERM to the viewer's session (start_new_session: the viewer and anything it started) where process
    groups exist (POSIX); elsewhere (Windows: no os.killpg, no sessions) the viewer alone is terminated."""
    if hasattr(os, "killpg"):
        os.killpg(process.pid, signal.SIGTERM)
    else:
        process.terminate()


def display_available() -> bool:
    """Whether a browser could show a window here (no display on a headless Linux box or over plain ssh)."""
    if sys.platform in ("darwin", "win32"):
        return True
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


@dataclass
class ViewerServer:
    """A running `rerun --serve-web` on loopback; `url` is the page to open, `grpc_url` where to log to."""

    process: subprocess.Popen[bytes]
    web_port: int
    grpc_port: int
    errors: IO[bytes]  # the program's stderr

    @property
    def grpc_url(self) -> str:
        return f"rerun+http://{LOOPBACK}:{self.grpc_port}/proxy"

    @property
    def url(self) -> str:
        return f"http://{LOOPBACK}:{self.web_port}/?url={urllib.parse.quote(self.grpc_url, safe='')}"

    def stop(self) -> None:
        if self.process.poll() is None:
            with contextlib.suppress(OSError):
                terminate_session(self.process)
            try:
                self.process.wait(5.0)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        self.errors.close()


def start_server(web_port: int | None = None, grpc_port: int | None = None) -> ViewerServer:
    """Start Rerun's web viewer and gRPC proxy on 127.0.0.1 (a port None or 0: a free one); wait until both
    listen. ViewError (one sentence) when a port is in use or the program fails."""
    import_rerun()
    check_ports(web_port, grpc_port)
    web = web_port or free_port()
    grpc = grpc_port or free_port()
    while grpc == web:
        grpc = free_port()
    command = [rerun_program(), "--serve-web", "--bind", LOOPBACK, "--port", str(grpc), "--web-viewer-port", str(web),
               "--server-memory-limit", "256MiB"]
    # its stderr goes to a file, not a pipe: a chatty viewer never blocks on a full pipe (ViewerServer.stop closes it)
    errors = tempfile.TemporaryFile()  # noqa: SIM115
    process = subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=errors,
                               start_new_session=True,
                               preexec_fn=_die_with_parent if sys.platform.startswith("linux") else None)
    server = ViewerServer(process, web, grpc, errors)
    try:
        _wait_listening(server)
    except ViewError:
        server.stop()
        raise
    return server


def _wait_listening(server: ViewerServer) -> None:
    deadline = time.monotonic() + START_TIMEOUT_S
    while time.monotonic() < deadline:
        if server.process.poll() is not None:
            server.errors.seek(0)
            detail = server.errors.read().decode(errors="replace")
            last = detail.strip().splitlines()[-1] if detail.strip() else f"exit status {server.process.returncode}"
            raise ViewError(f"The Rerun viewer did not start on {LOOPBACK} ports {server.web_port} and "
                            f"{server.grpc_port}: {last}")
        if _listening(server.web_port) and _listening(server.grpc_port):
            return
        time.sleep(0.05)
    raise ViewError(f"The Rerun viewer did not listen on {LOOPBACK}:{server.web_port} within {START_TIMEOUT_S:g} s.")


def _listening(port: int) -> bool:
    with contextlib.suppress(OSError), socket.create_connection((LOOPBACK, port), timeout=0.2):
        return True
    return False


def open_browser(url: str) -> bool:
    """Open the page where a display exists; returns whether it tried."""
    if not display_available():
        return False
    with contextlib.suppress(Exception):  # no browser configured: the printed URL is enough
        return webbrowser.open(url, new=2)
    return False
