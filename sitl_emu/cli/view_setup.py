"""`sitl-emu serve --view` / `--record-view`: the options checked before any port opens, and the live view started
on the runner (sitl_emu/view.py feeds it from each vehicle's snapshot). flightview is imported only when asked."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import click

from flightview.options import view_settings
from px4common.cli_style import UserError
from sitl_emu.cli.options import TOOL, UsageProblem

if TYPE_CHECKING:
    from flightview.launch import ViewHandle
    from sitl_emu.runtime.node import VehicleNode
    from sitl_emu.runtime.runner import RealTimeRunner
    from sitl_emu.vehicle.vehicle import Vehicle


def check_view(view: dict[str, Any]) -> None:
    """--view without the extra, on a port in use, or an unwritable --record-view: one sentence, before any port
    opens."""
    options = view_settings(**view)
    if options.wanted:
        from flightview.launch import check_view as check_view_ports
        from flightview.server import ViewError

        try:
            check_view_ports(options)
        except ViewError as err:
            raise UsageProblem(str(err)) from None


def start_view(vehicles: list[Vehicle], nodes: list[VehicleNode], view: dict[str, Any],
               runner: RealTimeRunner) -> ViewHandle | None:
    """--view / --record-view: the live view fed by a runner hook (sitl_emu/view.py), or None; one sentence on a
    problem (the nodes are closed first)."""
    options = view_settings(**view)
    if not options.wanted:
        return None
    from flightview.launch import open_view
    from flightview.server import ViewError
    from sitl_emu.view import ServeView

    try:
        handle = open_view("sitl-emu", ServeView.keys(vehicles), options, lambda line: click.echo(f"{TOOL}: {line}"))
    except ViewError as err:
        for node in nodes:
            node.close()
        raise UserError(str(err)) from None
    assert handle is not None
    runner.hooks.append(ServeView(handle, vehicles))
    return handle
