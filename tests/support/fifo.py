"""A FIFO joystick's writing end, for the end-to-end tests that feed joyfly js_event records through a FIFO."""

from __future__ import annotations

import errno
import os
import time
from pathlib import Path


def open_writer(fifo: Path, timeout_s: float) -> int:
    """The FIFO's writing end, once joyfly holds the reading end (until then the open fails with ENXIO)."""
    give_up = time.monotonic() + timeout_s
    while True:
        try:
            return os.open(fifo, os.O_WRONLY | os.O_NONBLOCK)
        except OSError as err:
            if err.errno != errno.ENXIO or time.monotonic() > give_up:
                raise
            time.sleep(0.05)
