"""The terminal console of `sitl-emu serve`: PX4's pxh> prompt on stdin/stdout.

A daemon thread only reads lines into a queue (sitl_emu/console/terminal.py: readline on a terminal, in the foreground
only); everything else happens in `pump()`, which the server loop calls each iteration on its own thread: run the
queued command lines through the Shell, print what a running command (`listener -n N`) prints, print the vehicle's
new events as PX4 console log lines ("INFO  [commander] Armed by internal command"), and show the prompt again.

With several vehicles (`--count`) the console controls one at a time: it says which at start, and the console-only
command `vehicle <sysid>` switches (PX4 has one pxh per instance; here one process holds them all).
"""

from __future__ import annotations

import errno
import logging
import queue
import sys
import threading
from collections.abc import Callable, Sequence
from typing import Any, TextIO

from sitl_emu.console.shell import Shell, log_line
from sitl_emu.console.terminal import PROMPT, JobControlGuard, make_input

log = logging.getLogger(__name__)

__all__ = ["PROMPT", "Console"]

_CLEAR_LINE = "\r\x1b[K"  # what pxh does before reprinting its prompt on a terminal


class Console:
    def __init__(self, vehicles: Sequence[Any], on_shutdown: Callable[[], None] | None = None,
                 stream_in: TextIO | None = None, stream_out: TextIO | None = None,
                 use_readline: bool | None = None) -> None:
        """`stream_in`/`stream_out` default to this process's stdin and stdout (then readline can edit lines)."""
        stream_in = sys.stdin if stream_in is None else stream_in
        stream_out = sys.stdout if stream_out is None else stream_out
        self.vehicles = list(vehicles)
        self.vehicle = self.vehicles[0]
        self._on_shutdown = on_shutdown
        self.shell = Shell(self.vehicle, self._shutdown if on_shutdown is not None else None,
                           {"vehicle": self._vehicle_command})
        self._stop_reading = threading.Event()
        self._input = make_input(stream_in, stream_out, self.shell.commands, self._stop_reading, use_readline)
        self._out: TextIO | None = stream_out
        self._lines: queue.SimpleQueue[str | None] = queue.SimpleQueue()
        self._idle = threading.Event()  # readline: the last command is done, the next prompt may come
        self._thread: threading.Thread | None = None
        self._guard = JobControlGuard()
        self._last_seq = -1  # print every event since boot, as PX4's console shows the boot log
        self._greeted = len(self.vehicles) == 1
        self._at_prompt = False
        self._was_foreground = True
        self._input_open = True
        self._stopped = False
        self._tty = _is_tty(stream_out)

    def start(self) -> None:
        """Start reading lines in a daemon thread (it never touches the vehicle)."""
        if self._thread is None:
            if self._input.wait.tty:
                self._guard.install()
            self._thread = threading.Thread(target=self._read_lines, name="sitl-emu-console", daemon=True)
            self._thread.start()

    def stop(self) -> None:
        """Stop printing, give the terminal back as it was; the reader thread ends with the process. (A prompt
        line stays open for what follows, as pxh's: "PX4 Exiting..." comes after a newline.)"""
        self._at_prompt = False
        self._stopped = True
        self._stop_reading.set()
        self._input.close()
        self._guard.restore()

    def pump(self) -> None:
        """Run queued commands, print output and new events, show the prompt. Call from the loop that owns the
        vehicle."""
        if self._stopped:
            return
        foreground = self._input.wait.foreground
        if foreground and not self._was_foreground:  # `fg`: the prompt line is gone, draw it again
            self._redraw_prompt()
        self._was_foreground = foreground
        self._print_events()
        self._run_queued_lines()
        if self.shell.busy:
            self._print(self.shell.poll())
        if not self.shell.busy and self._input_open and not self._stopped:
            self._prompt(foreground)

    # --- internals ---------------------------------------------------------------------------------------------
    def _run_queued_lines(self) -> None:
        while True:
            try:
                line = self._lines.get_nowait()
            except queue.Empty:
                return
            if line is None:  # end of input: no more prompts; log lines keep coming
                self._input_open = False
                continue
            self._at_prompt = False  # the user's Enter ended the prompt line
            if self.shell.busy:  # a line typed while `listener -n` prints stops it (PX4: any key)
                self.shell.cancel()
                continue
            self._write(self.shell.execute(line))
            self._print_events()

    def _prompt(self, foreground: bool) -> None:
        if self._input.draws_prompt:
            self._idle.set()  # readline shows the prompt itself
        elif not self._at_prompt and foreground:
            self._write(PROMPT)
            self._at_prompt = True

    def _redraw_prompt(self) -> None:
        if self._input.draws_prompt:
            if self._input.at_prompt:
                self._write("\n")
                self._input.redisplay()
        else:
            self._at_prompt = False

    def _shutdown(self) -> None:
        self._input_open = False  # `shutdown`: no prompt after "Exiting NOW."
        if self._on_shutdown is not None:
            self._on_shutdown()

    def _read_lines(self) -> None:
        reader = self._input
        while not self._stop_reading.is_set():
            if reader.draws_prompt and not self._wait_until_idle():
                return
            try:
                line = reader.read_line()
            except Exception:  # the console must never take the vehicle down
                log.exception("console input failed")
                line = None
            if line is None:
                break
            self._lines.put(line)
            self._idle.clear()  # after the put: the next pump runs the line, then sets it again
        self._lines.put(None)

    def _wait_until_idle(self) -> bool:
        """Readline: wait until the last command is done before showing the prompt again; a line typed meanwhile
        is passed on (it stops a running `listener -n`). False when the console stops."""
        while not self._idle.wait(0.1):
            if self._stop_reading.is_set():
                return False
            typed = self._input.line_typed_meanwhile()
            if typed is not None:
                self._lines.put(typed)
        return not self._stop_reading.is_set()

    def _print_events(self) -> None:
        events = self.vehicle.events_after(self._last_seq)
        text = "".join(event.console_line + "\n" for event in events)
        if events:
            self._last_seq = events[-1].seq
        if not self._greeted:
            self._greeted = True
            text += self._greeting()
        self._print(text)

    def _print(self, text: str) -> None:
        """Text that does not answer a command line: above the prompt, which is drawn again below it."""
        if not text:
            return
        reader = self._input
        if reader.draws_prompt and reader.at_prompt:
            self._write(_CLEAR_LINE + text)
            reader.redisplay()
            return
        if self._at_prompt:
            self._write(_CLEAR_LINE if self._tty else "\n")
            self._at_prompt = False
        self._write(text)

    def _write(self, text: str) -> None:
        if not text or self._out is None:
            return
        try:
            self._out.write(text)
            self._out.flush()
        except OSError as err:
            if err.errno != errno.EIO:  # EIO: a background write with `stty tostop`; the next one may work
                self._out = None  # closed terminal or pipe: keep serving, stop printing
        except ValueError:
            self._out = None

    # --- vehicle: which vehicle this console controls ------------------------------------------------------------
    def _greeting(self) -> str:
        return log_line("INFO", "vehicle", f"console controls sysid {self.vehicle.sysid} (vehicle 1 of "
                                           f"{len(self.vehicles)}, sysids {_sysid_list(self.vehicles)}); "
                                           "'vehicle <sysid>' switches")

    def _vehicle_command(self, args: list[str]) -> tuple[int, str]:
        if not args:
            return 0, log_line("INFO", "vehicle", f"console controls sysid {self.vehicle.sysid}; vehicles (sysid): "
                                                  f"{_sysid_list(self.vehicles)}")
        chosen = [v for v in self.vehicles if args[0].isdigit() and int(v.sysid) == int(args[0])]
        if len(args) > 1 or not chosen:
            return 1, log_line("ERROR", "vehicle", f"no vehicle with sysid {' '.join(args)}; "
                                                   f"use one of {_sysid_list(self.vehicles)}")
        self._select(chosen[0])
        return 0, log_line("INFO", "vehicle", f"console controls sysid {self.vehicle.sysid}")

    def _select(self, vehicle: Any) -> None:
        """Control `vehicle` from now on; its log lines show from now on (not its history)."""
        self.vehicle = vehicle
        self.shell.vehicle = vehicle
        self.shell.cancel()
        events = vehicle.events_after(-1)
        self._last_seq = events[-1].seq if events else -1


def _sysid_list(vehicles: Sequence[Any]) -> str:
    sysids = [int(v.sysid) for v in vehicles]
    if len(sysids) > 2 and sysids == list(range(sysids[0], sysids[-1] + 1)):
        return f"{sysids[0]}-{sysids[-1]}"
    return ", ".join(str(s) for s in sysids)


def _is_tty(stream: TextIO) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):
        return False


def attach_console(vehicles: Sequence[Any], runner: Any, enabled: bool) -> Console | None:
    """The pxh> console on this terminal, pumped by `runner` and stopping it on `shutdown`; None without one."""
    if not enabled or not sys.stdin.isatty():
        return None
    console = Console(vehicles, runner.stop)
    console.start()
    runner.hooks.append(console.pump)
    return console
