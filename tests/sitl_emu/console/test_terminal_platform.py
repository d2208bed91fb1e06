"""Both sides of the console's terminal seam (sitl_emu/console/terminal.py `posix_terminal`): job control and
select() on the terminal where they exist (Linux, macOS), plain blocking line reads where they do not (Windows,
simulated here by taking os.tcgetpgrp and SIGTTIN/SIGTTOU away)."""

from __future__ import annotations

import os
import signal
import threading

import pytest

from sitl_emu.console import terminal
from sitl_emu.console.terminal import JobControlGuard, StreamInput, is_foreground, posix_terminal

pytestmark = pytest.mark.skipif(os.name != "posix", reason="the POSIX side needs a POSIX host (CI is Linux)")


def _windows_like(monkeypatch: pytest.MonkeyPatch) -> None:
    for name in ("tcgetpgrp", "getpgrp"):
        monkeypatch.delattr(os, name, raising=False)
    for name in ("SIGTTIN", "SIGTTOU"):
        monkeypatch.delattr(signal, name, raising=False)


def test_on_posix_the_console_ignores_sigttin_while_it_runs_and_restores_it() -> None:
    assert posix_terminal()
    before = signal.getsignal(signal.SIGTTIN)
    guard = JobControlGuard()
    guard.install()
    assert signal.getsignal(signal.SIGTTIN) == signal.SIG_IGN
    guard.restore()
    assert signal.getsignal(signal.SIGTTIN) == before
    master, slave = os.openpty()
    try:
        assert not is_foreground(slave)  # a pty that is not our controlling terminal is never read
    finally:
        os.close(master)
        os.close(slave)


def test_without_job_control_the_console_reads_the_terminal_without_select(monkeypatch: pytest.MonkeyPatch) -> None:
    _windows_like(monkeypatch)

    def no_select(*args: object) -> None:
        raise OSError(10038, "An operation was attempted on something that is not a socket")  # as on Windows
    monkeypatch.setattr(terminal.select, "select", no_select)
    assert not posix_terminal()
    guard = JobControlGuard()
    guard.install()  # nothing to install, and no AttributeError
    guard.restore()
    master, slave = os.openpty()
    with os.fdopen(slave, "r", closefd=True) as stream:
        try:
            assert is_foreground(slave)
            reader = StreamInput(stream, threading.Event())  # type: ignore[arg-type]
            assert reader.wait.tty
            os.write(master, b"commander status\n")
            assert reader.read_line() == "commander status"
        finally:
            os.close(master)


def test_readline_input_looks_for_typed_lines_only_where_select_takes_terminals(
        monkeypatch: pytest.MonkeyPatch) -> None:
    _windows_like(monkeypatch)
    monkeypatch.setattr(terminal.select, "select", lambda *a: pytest.fail("select() on a terminal off POSIX"))
    reader = terminal.ReadlineInput.__new__(terminal.ReadlineInput)
    reader.wait = terminal._TerminalWait(0, threading.Event())
    assert reader.line_typed_meanwhile() is None
