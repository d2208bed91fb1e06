"""A PNG of a ULog flight, for CI artifacts: position against setpoint per axis, and the modes over time.

The position is vehicle_local_position x/y/z; the setpoint vehicle_local_position_setpoint x/y/z, or where that is
not logged trajectory_setpoint position[0..2] (PX4 topic and field names, as summary.py reads them). matplotlib is
the optional extra `plot` (pip install -e '.[plot]' in the clone); it draws off screen (Agg), so no display is needed.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from sitl_emu.cli.extras import install_command
from sitl_emu.log.summary import PLOT_PACKAGES, LogSummary, series

__all__ = ["INSTALL_HINT", "PlotUnavailable", "plot_log"]

INSTALL_HINT = f"--plot needs matplotlib, which is not installed: {install_command('plot', PLOT_PACKAGES)}"
AXES = (("x", 0, "North x [m]"), ("y", 1, "East y [m]"), ("z", 2, "Down z [m]"))


class PlotUnavailable(Exception):
    """matplotlib is not installed; str() says how to install it."""


def _pyplot() -> Any:
    try:
        import matplotlib
    except ImportError:
        raise PlotUnavailable(INSTALL_HINT) from None
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _setpoint(ulog: Any, axis: str, index: int) -> tuple[np.ndarray, np.ndarray] | None:
    return series(ulog, "vehicle_local_position_setpoint", axis) or series(
        ulog, "trajectory_setpoint", f"position[{index}]")


def _draw_axis(ax: Any, ulog: Any, axis: str, index: int, label: str) -> None:
    position = series(ulog, "vehicle_local_position", axis)
    if position is not None:
        ax.plot(*position, label="vehicle_local_position", linewidth=1.2)
    setpoint = _setpoint(ulog, axis, index)
    if setpoint is not None:
        ax.plot(*setpoint, label="setpoint", linestyle="--", linewidth=1.0)
    ax.set_ylabel(label)
    ax.grid(True, alpha=0.3)
    if position is not None or setpoint is not None:
        ax.legend(loc="upper right", fontsize="small")


def _draw_modes(ax: Any, summary: LogSummary) -> None:
    names = list(dict.fromkeys(m.name for m in summary.modes))
    if summary.modes:
        times = [m.start_s for m in summary.modes] + [summary.duration_s]
        levels = [names.index(m.name) for m in summary.modes]
        ax.step(times, levels + levels[-1:], where="post", linewidth=1.5)
    ax.set_yticks(range(len(names)), names)
    ax.set_ylabel("mode")
    ax.set_xlabel("time [s]")
    ax.grid(True, alpha=0.3)


def plot_log(ulog: Any, summary: LogSummary, out: str | Path) -> Path:
    """Write the PNG to `out`; PlotUnavailable without matplotlib."""
    plt = _pyplot()
    fig, axes = plt.subplots(4, 1, sharex=True, figsize=(10, 10))
    try:
        for ax, (axis, index, label) in zip(axes[:3], AXES, strict=True):
            _draw_axis(ax, ulog, axis, index, label)
        _draw_modes(axes[3], summary)
        fig.suptitle(f"{summary.path.name}: {summary.duration_s:.1f} s")
        fig.tight_layout()
        fig.savefig(out, format="png", dpi=80)
    finally:
        plt.close(fig)
    return Path(out)
