"""The live view's command-line options, the same for `sitl-emu serve` and `joyfly fly|demo`."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import click

from flightview.launch import ViewOptions
from flightview.server import INSTALL_COMMAND


class PortRange(click.IntRange):
    """A TCP port, its range said as both programs say theirs ("1 to 65535": px4common.cli_style.describe_range,
    which flightview does not import)."""

    def _describe_range(self) -> str:
        return f"{self.min} to {self.max}"


PORT_RANGE = PortRange(1, 65535)


def view_options(command: Callable[..., Any]) -> Callable[..., Any]:
    """--view, --view-port, --view-grpc-port, --record-view on a click command (passed as view, view_port,
    view_grpc_port, record_view)."""
    command = click.option("--record-view", type=click.Path(dir_okay=False, path_type=Path), default=None,
                           metavar="FILE.rrd", help="Save the view's recording to this file (replay it with "
                                                    "`rerun FILE.rrd`); works with or without --view.")(command)
    command = click.option("--view-grpc-port", type=PORT_RANGE, default=None,
                           show_default="a free one",
                           help="Port of the view's data stream (Rerun's gRPC proxy, which the page reads) on "
                                "127.0.0.1 (implies --view).")(command)
    command = click.option("--view-port", type=PORT_RANGE, default=None, show_default="a free one",
                           help="Port of the view's web page on 127.0.0.1 (implies --view).")(command)
    return click.option("--view", is_flag=True, help="Show the flight live in a web browser on this machine: the "
                         "vehicle, trail, setpoint, home and fence in 3D, and plots (needs the view extra: "
                         f"{INSTALL_COMMAND} in the joyfly clone).")(command)


def view_settings(view: bool = False, view_port: int | None = None, record_view: Path | None = None,
                  view_grpc_port: int | None = None) -> ViewOptions:
    return ViewOptions(view=view, port=view_port, record=record_view, grpc_port=view_grpc_port)
