"""Starting and stopping the view for a command line: --view, --view-port, --record-view.

`open_view` starts the loopback viewer (server.py) when the view is wanted, checks that the recording file can be
written, prints the page's URL, opens a browser where there is a display, and returns a ViewHandle that the caller
feeds (`live`) and closes. Problems are a ViewError in one sentence, raised before anything flies.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from flightview.live import LiveView
from flightview.server import ViewError, ViewerServer, check_ports, import_rerun, open_browser, start_server


@dataclass(frozen=True, slots=True)
class ViewOptions:
    """--view (or --view-port / --view-grpc-port, which imply it), --view-port (the page's; None: a free port),
    --view-grpc-port (the data stream's, Rerun's gRPC proxy; None: a free port), --record-view FILE.rrd."""

    view: bool = False
    port: int | None = None
    record: Path | None = None
    grpc_port: int | None = None

    @property
    def serve(self) -> bool:
        return self.view or self.port is not None or self.grpc_port is not None

    @property
    def wanted(self) -> bool:
        return self.serve or self.record is not None


@dataclass
class ViewHandle:
    live: LiveView
    server: ViewerServer | None

    def close(self) -> None:
        try:
            self.live.close()
        finally:
            if self.server is not None:
                self.server.stop()


def check_view(options: ViewOptions) -> None:
    """Before anything opens: ViewError in one sentence if the extra is missing, --view-port is in use or the
    recording cannot be written."""
    if not options.wanted:
        return
    import_rerun()
    check_ports(options.port, options.grpc_port)
    if options.record is not None:
        _check_writable(options.record)


def open_view(app_id: str, keys: Sequence[str], options: ViewOptions, say: Callable[[str], None],
              browser: Callable[[str], bool] = open_browser) -> ViewHandle | None:
    """The running view for `options` (None when not wanted); `say` prints one line to the user."""
    if not options.wanted:
        return None
    check_view(options)
    server = start_server(options.port, options.grpc_port) if options.serve else None
    try:
        live = LiveView(app_id, keys, server, options.record)
    except BaseException:
        if server is not None:
            server.stop()
        raise
    if server is not None:
        opened = browser(server.url)
        say(f"live view: {server.url}" + ("" if opened else " (open it in a browser on this machine)"))
    if options.record is not None:
        say(f"recording the view to {options.record} (replay: rerun {options.record})")
    return ViewHandle(live, server)


def _check_writable(path: Path) -> None:
    try:
        with path.open("wb"):
            pass
    except OSError as err:
        raise ViewError(f"Cannot write the view recording {path}: {err.strerror}.") from None
