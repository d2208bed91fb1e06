"""A node's flight logs: the logger on its tick, and its log directory served by LOG_REQUEST_LIST / LOG_REQUEST_DATA.

PX4 SITL writes its logs under ./log of its working directory and its mavlink log handler lists that same directory
(src/modules/mavlink/mavlink_log_handler.cpp); each instance of a multi-vehicle SITL has its own working directory,
so here vehicle `instance` of a --count gets `<dir>-<instance>` beside the first one's (as its parameter file).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from pathlib import Path

from sitl_emu.log.flight_log import FlightLogger
from sitl_emu.mavlink.endpoint import load_handler_classes
from sitl_emu.mavlink.protocols.ftp import FtpProtocol
from sitl_emu.mavlink.protocols.log import DirectoryLogSource, LogProtocol
from sitl_emu.runtime.node import VehicleNode

DEFAULT_LOG_DIR = Path("log")  # PX4 SITL: LOG_ROOT = PX4_STORAGEDIR "/log", the working directory's log/


def instance_log_dir(base: str | os.PathLike[str], instance: int, first: int = 0) -> Path:
    """Vehicle `instance`'s log directory: `base` for the first vehicle, `<base>-<instance>` for the others."""
    path = Path(base)
    return path if instance == first else path.with_name(f"{path.name}-{instance}")


def handler_classes(directory: str | os.PathLike[str],
                    params_file: str | os.PathLike[str] | None = None) -> Sequence[type]:
    """A node's protocol handlers: its log protocol serving `directory`, and its FTP root showing `directory` as
    log/ and `params_file` (if any) under its name, read-only, as PX4 SITL's working directory holds them."""
    serving = LogProtocol.with_source(DirectoryLogSource(directory))
    mounts: dict[str, str | os.PathLike[str]] = {"log": directory}
    if params_file is not None:
        mounts[Path(params_file).name] = params_file
    ftp = FtpProtocol.with_root(FtpProtocol.root, {**FtpProtocol.mounts, **mounts}, metadata=FtpProtocol.metadata)
    replaced: dict[type, type] = {LogProtocol: serving, FtpProtocol: ftp}
    return [replaced.get(cls, cls) for cls in load_handler_classes()]


def attach_logger(node: VehicleNode, directory: str | os.PathLike[str]) -> FlightLogger:
    """A FlightLogger for `node`, run at the start of every step_io."""
    logger = FlightLogger(node, directory)
    node.tick_hooks.append(logger.tick)
    return logger


def handlers_by_instance(base: str | os.PathLike[str], first: int = 0,
                         params_file: Callable[[int], Path] | None = None) -> Callable[[int], Sequence[type]]:
    """build_nodes' `handlers_for`: each instance's handlers serve that instance's log directory (and parameter
    file, `params_file(instance)`)."""
    return lambda instance: handler_classes(instance_log_dir(base, instance, first),
                                            None if params_file is None else params_file(instance))


def attach_loggers(nodes: Sequence[VehicleNode], base: str | os.PathLike[str], first: int = 0) -> list[FlightLogger]:
    """A logger on each node (node i is instance first + i), each writing its instance's log directory."""
    return [attach_logger(node, instance_log_dir(base, first + i, first)) for i, node in enumerate(nodes)]
