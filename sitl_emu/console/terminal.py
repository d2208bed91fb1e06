"""Where the pxh> console's lines come from: a text stream, or the terminal through the standard library's readline.

Job control. A process that reads its controlling terminal while it is a background job gets SIGTTIN and stops
("Stopped (tty input)" after `sitl-emu serve &`), and a stopped process runs no SIGTERM handler until it is
continued. So the console reads the terminal only while the process is the terminal's foreground job
(os.tcgetpgrp(fd) == os.getpgrp()), and checks again every POLL_S, so `fg` and `bg` work later. While the console
runs, SIGTTIN and SIGTTOU are ignored: a read that races with `bg` then fails with EIO (and is retried in the
foreground) instead of stopping the process. A terminal that is not the controlling one (tcgetpgrp fails) is not
read at all.

Job control and select() on a terminal are POSIX: on Windows (no os.tcgetpgrp, no SIGTTIN, select() takes sockets
only) `posix_terminal()` is False, the console is always in the foreground and blocks in its reader thread's
readline() instead (a daemon thread: it does not keep the process alive at the end).

Readline gives line editing, history (in memory only: nothing is written to the user's home) with PX4's
"commander takeoff" already in it (pxh.cpp Pxh::Pxh adds it "for convenience"), and Tab completion of command
names (as pxh.cpp _tab_completion). Where readline is missing the terminal is read line by line.
On a terminal, Ctrl-D does not end the console, as in pxh (its getchar() loop ignores EOF); on a pipe or a file, the
end of input ends it.
"""

from __future__ import annotations

import contextlib
import errno
import os
import select
import signal
import sys
import threading
from collections.abc import Sequence
from types import ModuleType
from typing import Any, TextIO

try:
    import termios
except ImportError:  # not a POSIX system: no terminal modes to save
    termios = None  # type: ignore[assignment]

_TERMIOS_ERRORS: tuple[type[Exception], ...] = (OSError,) if termios is None else (OSError, termios.error)

PROMPT = "pxh> "
POLL_S = 0.2  # how often a background console looks whether it is in the foreground again
TAKEOFF_HISTORY = "commander takeoff"  # pxh.cpp: _history.try_to_add("commander takeoff"); // for convenience


def posix_terminal() -> bool:
    """Whether the platform has job control on its terminals and select() on them (POSIX: Linux, macOS), the seam
    between the two ways of reading the terminal."""
    return (os.name == "posix" and hasattr(os, "tcgetpgrp") and hasattr(os, "getpgrp")
            and hasattr(signal, "SIGTTIN") and hasattr(signal, "SIGTTOU"))


def is_foreground(fd: int) -> bool:
    """True if this process is the foreground job of the terminal `fd` (False if `fd` is not our terminal); always
    True where there is no job control."""
    if not posix_terminal():
        return True
    try:
        return os.tcgetpgrp(fd) == os.getpgrp()
    except OSError:
        return False


def _fileno(stream: Any) -> int | None:
    try:
        return int(stream.fileno())
    except (AttributeError, ValueError, OSError):  # io.StringIO and closed streams have none
        return None


class JobControlGuard:
    """Ignore SIGTTIN and SIGTTOU while the console reads a terminal; `restore()` puts the old handlers back."""

    def __init__(self) -> None:
        self._previous: dict[int, Any] = {}

    def install(self) -> None:
        if not posix_terminal():  # no background jobs to guard against
            return
        for sig in (signal.SIGTTIN, signal.SIGTTOU):
            try:
                self._previous[sig] = signal.signal(sig, signal.SIG_IGN)
            except ValueError:  # not the main thread (a library user's console): leave job control alone
                return

    def restore(self) -> None:
        for sig, handler in self._previous.items():
            with contextlib.suppress(ValueError, TypeError):
                signal.signal(sig, handler)
        self._previous.clear()


class _TerminalWait:
    """Waits until the terminal has input for this process while it is the foreground job."""

    def __init__(self, fd: int | None, stop: threading.Event) -> None:
        self.fd = fd
        self.tty = fd is not None and os.isatty(fd)
        self.stop = stop

    @property
    def foreground(self) -> bool:
        """May we read (and prompt)? Always for a pipe or a file; on a terminal only as its foreground job."""
        return not self.tty or is_foreground(self.fd)  # type: ignore[arg-type]

    def until_foreground(self) -> bool:
        """Block while in the background; False when the console is stopped."""
        while not self.stop.is_set():
            if self.foreground:
                return True
            self.stop.wait(POLL_S)
        return False

    def until_input(self) -> bool:
        """Block until a line (or an EOF) is waiting for us in the foreground; False when the console is stopped."""
        while self.until_foreground():
            fd = self.fd
            if fd is None or not self.tty or not posix_terminal():  # Windows: block in readline() instead
                return True
            try:
                readable = select.select([fd], [], [], POLL_S)[0]
            except (OSError, ValueError):
                return False
            if readable and self.foreground:
                return True
        return False


class StreamInput:
    """Lines from a text stream: a pipe, a file, or a terminal where readline is missing. The console prompts."""

    draws_prompt = False
    at_prompt = False  # readline's notion; the console keeps its own for this input

    def __init__(self, stream: TextIO, stop: threading.Event) -> None:
        self._stream = stream
        self.wait = _TerminalWait(_fileno(stream), stop)

    def read_line(self) -> str | None:
        """The next line without its line end; None at the end of a pipe or file, or when the console stops."""
        while self.wait.until_input():
            try:
                line = self._stream.readline()
            except OSError as err:
                if err.errno == errno.EIO and self.wait.tty:  # lost a race with `bg`: read again in the foreground
                    continue
                return None
            except ValueError:  # closed
                return None
            if line:
                return line.rstrip("\r\n")
            if not self.wait.tty:
                return None
            self.wait.stop.wait(0.05)  # Ctrl-D on a terminal: ignored, as pxh does (and a hung-up one: no spinning)
        return None

    def line_typed_meanwhile(self) -> str | None:
        return None  # the reader thread reads on; lines typed while a command runs reach the console anyway

    def redisplay(self) -> None:
        """The console reprints the prompt itself."""

    def close(self) -> None:
        """Nothing to undo."""


class ReadlineInput:
    """The terminal through readline: input(PROMPT) draws the prompt and edits the line.

    `at_prompt` is True from the moment readline has shown the prompt (its pre-input hook) until input() returns:
    the console then prints log lines above the prompt and calls `redisplay()`.
    """

    draws_prompt = True

    def __init__(self, readline: ModuleType, commands: Sequence[str], stop: threading.Event) -> None:
        self._readline = readline
        self.wait = _TerminalWait(sys.stdin.fileno(), stop)
        self.at_prompt = False
        self._saved_modes = _terminal_modes(self.wait.fd)
        self._commands = sorted(commands)
        readline.set_completer(self._complete)
        readline.set_completer_delims(" \t")
        readline.parse_and_bind("bind ^I rl_complete" if "libedit" in (readline.__doc__ or "") else "tab: complete")
        readline.clear_history()
        readline.add_history(TAKEOFF_HISTORY)
        readline.set_pre_input_hook(self._prompt_shown)

    def read_line(self) -> str | None:
        while self.wait.until_foreground():
            try:
                return input(PROMPT)
            except EOFError:  # Ctrl-D (ignored, as pxh does), or a read that lost a race with `bg`
                if self.wait.foreground:
                    with contextlib.suppress(OSError, ValueError):
                        sys.stdout.write("\n")
                        sys.stdout.flush()
                self.wait.stop.wait(0.05)  # a hung-up terminal answers EOF at once: do not spin
            finally:
                self.at_prompt = False
        return None

    def line_typed_meanwhile(self) -> str | None:
        """A line typed while a command runs (the terminal is in its normal line mode then), or None."""
        fd = self.wait.fd
        assert fd is not None
        if not posix_terminal() or not self.wait.foreground or not select.select([fd], [], [], 0)[0]:
            return None
        try:
            return os.read(fd, 4096).decode("utf-8", errors="replace").rstrip("\r\n")
        except OSError:
            return None

    def redisplay(self) -> None:
        """Draw the prompt and the line being edited again, below what the console just printed.

        readline.redisplay() would not do it: rl_redisplay() only draws what differs from what readline believes is
        on the screen, and that has not changed. The cursor ends after the text, where readline left it unless the
        user had moved it back into the line (then the next key puts it right).
        """
        text = PROMPT + self._readline.get_line_buffer()
        with contextlib.suppress(OSError, ValueError):
            sys.stdout.write(text)
            sys.stdout.flush()

    def close(self) -> None:
        """Leave the terminal as it was if we stop while readline has it (no echo, raw keys)."""
        self._readline.set_pre_input_hook(None)
        fd = self.wait.fd
        if self.at_prompt and self._saved_modes is not None and fd is not None and self.wait.foreground:
            with contextlib.suppress(*_TERMIOS_ERRORS):
                termios.tcsetattr(fd, termios.TCSADRAIN, self._saved_modes)

    def _prompt_shown(self) -> None:
        self.at_prompt = True

    def _complete(self, text: str, state: int) -> str | None:
        if self._readline.get_begidx() != 0:  # only the command word, as pxh completes
            return None
        matches = [name + " " for name in self._commands if name.startswith(text)]
        return matches[state] if state < len(matches) else None


def _terminal_modes(fd: int | None) -> Any:
    if fd is None or termios is None:
        return None
    try:
        return termios.tcgetattr(fd)
    except _TERMIOS_ERRORS:
        return None


def make_input(stream_in: TextIO, stream_out: TextIO, commands: Sequence[str], stop: threading.Event,
               use_readline: bool | None = None) -> StreamInput | ReadlineInput:
    """Readline when the console is this process's terminal (stdin and stdout) and readline exists, else a stream.

    `use_readline` False forces the stream; None (default) and True use readline where it can work.
    """
    if use_readline is not False and stream_in is sys.stdin and stream_out is sys.stdout and _both_ttys():
        readline = _import_readline()
        if readline is not None:
            return ReadlineInput(readline, commands, stop)
    return StreamInput(stream_in, stop)


def _both_ttys() -> bool:
    try:
        return sys.stdin.isatty() and sys.stdout.isatty()
    except (AttributeError, ValueError):
        return False


def _import_readline() -> ModuleType | None:
    try:
        import readline
    except ImportError:  # Windows, or a Python built without it: plain lines
        return None
    return readline
