"""The terminal console of `sitl-emu serve`: PX4's pxh> prompt on stdin/stdout.

A daemon thread only reads lines into a queue; everything else happens in `pump()`, which the server loop calls each
iteration on its own thread: run the queued command lines through the Shell, print the vehicle's new events as PX4
console log lines ("INFO  [commander] Armed by internal command"), and show the "pxh> " prompt again.
"""

from __future__ import annotations

import logging
import queue
import sys
import threading
from collections.abc import Callable
from typing import Any, TextIO

from sitl_emu.shell import Shell

log = logging.getLogger(__name__)

PROMPT = "pxh> "
_CLEAR_LINE = "\r\x1b[K"  # what pxh does before reprinting its prompt on a terminal


class Console:
    def __init__(self, vehicle: Any, on_shutdown: Callable[[], None] | None = None,
                 stream_in: TextIO = sys.stdin, stream_out: TextIO = sys.stdout) -> None:
        self.vehicle = vehicle
        self._on_shutdown = on_shutdown
        self.shell = Shell(vehicle, self._shutdown if on_shutdown is not None else None)
        self._in = stream_in
        self._out: TextIO | None = stream_out
        self._lines: queue.SimpleQueue[str | None] = queue.SimpleQueue()
        self._thread: threading.Thread | None = None
        self._last_seq = -1  # print every event since boot, as PX4's console shows the boot log
        self._at_prompt = False
        self._input_open = True
        self._stopped = False
        self._tty = _is_tty(stream_out)

    def start(self) -> None:
        """Start reading lines in a daemon thread (it never touches the vehicle)."""
        if self._thread is None:
            self._thread = threading.Thread(target=self._read_lines, name="sitl-emu-console", daemon=True)
            self._thread.start()

    def stop(self) -> None:
        """Stop printing; the reader thread is a daemon blocked on input and ends with the process."""
        if self._at_prompt:
            self._write("\n")
            self._at_prompt = False
        self._stopped = True

    def pump(self) -> None:
        """Run queued commands, print new events, show the prompt. Call from the loop that owns the vehicle."""
        if self._stopped:
            return
        self._print_events()
        while True:
            try:
                line = self._lines.get_nowait()
            except queue.Empty:
                break
            if line is None:  # EOF: no more input, no more prompts; log lines keep coming
                self._input_open = False
                continue
            self._at_prompt = False  # the user's Enter ended the prompt line
            self._write(self.shell.execute(line))
            self._print_events()
        if self._input_open and not self._at_prompt and not self._stopped:
            self._write(PROMPT)
            self._at_prompt = True

    # --- internals ---------------------------------------------------------------------------------------------
    def _shutdown(self) -> None:
        self._input_open = False  # `shutdown`: no prompt after "Exiting NOW."
        if self._on_shutdown is not None:
            self._on_shutdown()

    def _read_lines(self) -> None:
        try:
            for line in self._in:
                self._lines.put(line.rstrip("\r\n"))
        except (OSError, ValueError) as err:  # closed or unreadable stdin: end quietly
            log.debug("console input ended: %s", err)
        self._lines.put(None)

    def _print_events(self) -> None:
        events = self.vehicle.events_after(self._last_seq)
        if not events:
            return
        self._last_seq = events[-1].seq
        if self._at_prompt:
            self._write(_CLEAR_LINE if self._tty else "\n")
            self._at_prompt = False
        self._write("".join(event.console_line + "\n" for event in events))

    def _write(self, text: str) -> None:
        if not text or self._out is None:
            return
        try:
            self._out.write(text)
            self._out.flush()
        except (OSError, ValueError):  # closed terminal or pipe: keep serving, stop printing
            self._out = None


def _is_tty(stream: TextIO) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):
        return False
