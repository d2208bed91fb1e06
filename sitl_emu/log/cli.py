"""`sitl-emu log FILE.ulg`: a ULog file summarised in the terminal, and with --plot drawn to a PNG (issue 15).

sitl_emu/cli/main.py only lists this command; summary.py reads the file, plot.py draws it.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from px4common.cli_style import UserError
from sitl_emu.cli.extras import in_clone
from sitl_emu.log.summary import LogError, LogSummary, format_summary, read_ulog, summarise

__all__ = ["log"]


HELP = ("Summarise FILE.ulg (a log sitl-emu or PX4 wrote): duration, modes over time, maximum altitude above the start "
        "and horizontal speed, and the logged texts with their times. Reads it with pyulog (the plot extra: "
        f"{in_clone('plot')}).")


@click.command(short_help="Summarise a ULog file; --plot draws it to a PNG.", help=HELP)
@click.argument("ulg_file", metavar="FILE.ulg", type=click.Path(path_type=Path))
@click.option("--plot", "plot_out", metavar="OUT.png", type=click.Path(path_type=Path), default=None,
              help="Also draw position against setpoint per axis and the modes over time to OUT.png "
                   f"(needs matplotlib, the plot extra: {in_clone('plot')}).")
def log(ulg_file: Path, plot_out: Path | None) -> None:
    """Summarise a ULog file (the command's help is HELP)."""
    try:
        ulog = read_ulog(ulg_file)
    except LogError as err:
        raise UserError(str(err)) from None
    summary = summarise(ulog, ulg_file)
    click.echo(format_summary(summary))
    if plot_out is not None:
        _plot(ulog, summary, plot_out)


def _plot(ulog: Any, summary: LogSummary, out: Path) -> None:
    from sitl_emu.log.plot import PlotUnavailable, plot_log  # matplotlib only when asked for

    try:
        written = plot_log(ulog, summary, out)
    except PlotUnavailable as err:
        raise UserError(str(err)) from None
    except OSError as err:
        raise UserError(f"cannot write {out}: {err.strerror or err}.") from None
    click.echo(f"Plot: {written}")
