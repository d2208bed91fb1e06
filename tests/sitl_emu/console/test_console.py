"""The terminal console: lines from stdin run as pxh> commands; vehicle events print as PX4 log lines."""

from __future__ import annotations

import io
import sys
import threading
import types

import pytest
from support.handler_ctx import FakeVehicle

from sitl_emu.console import terminal
from sitl_emu.console.console import PROMPT, Console
from sitl_emu.console.terminal import ReadlineInput, StreamInput, make_input
from sitl_emu.px4 import Severity


def _run(vehicle: FakeVehicle, text: str, on_shutdown=None) -> tuple[Console, io.StringIO]:
    out = io.StringIO()
    console = Console([vehicle], on_shutdown, stream_in=io.StringIO(text), stream_out=out)
    console.start()
    assert console._thread is not None
    console._thread.join(timeout=5)
    console.pump()
    return console, out


def _arm_reports(vehicle: FakeVehicle) -> None:
    def react(cmd):
        if cmd.command == 400:
            vehicle.report(Severity.INFO, "commander", "Armed by internal command")
    vehicle.on_command = react


def test_command_runs_and_its_event_prints_as_console_line():
    vehicle = FakeVehicle()
    _arm_reports(vehicle)
    _, out = _run(vehicle, "commander arm\n")
    assert [c.command for c in vehicle.commands] == [400]
    assert "INFO  [commander] Armed by internal command\n" in out.getvalue()


def test_a_text_that_names_its_module_prints_it_once():
    """The flight logger's text is "[logger] ./log/...ulg" (its STATUSTEXT, as PX4's); the console line names the
    module once, as PX4's console does."""
    vehicle = FakeVehicle()
    vehicle.report(Severity.INFO, "logger", "[logger] ./log/2026-01-02/03_04_05.ulg")
    out = io.StringIO()
    Console([vehicle], stream_in=io.StringIO(""), stream_out=out).pump()
    assert out.getvalue().startswith("INFO  [logger] ./log/2026-01-02/03_04_05.ulg\n")
    assert vehicle.events_after(-1)[-1].statustext_text == "[logger] ./log/2026-01-02/03_04_05.ulg\t"


def test_boot_events_then_prompt():
    vehicle = FakeVehicle()
    vehicle.report(Severity.INFO, "commander", "Ready for takeoff!")
    out = io.StringIO()
    console = Console([vehicle], stream_in=io.StringIO(""), stream_out=out)
    console.pump()  # before the reader has seen EOF: shows the log and a prompt
    assert out.getvalue() == "INFO  [commander] Ready for takeoff!\n" + PROMPT


def test_output_of_each_command_then_prompt():
    vehicle = FakeVehicle()
    out = io.StringIO()
    console = Console([vehicle], stream_in=io.StringIO(""), stream_out=out)
    console.pump()
    console._lines.put("param get MAV_SYS_ID")
    console._lines.put("nonsense")
    console.pump()
    assert out.getvalue() == (PROMPT + "1\n" + "Invalid command: nonsense\ntype 'help' for a list of commands\n"
                              + PROMPT)


def test_events_arriving_later_are_printed_on_their_own_line():
    vehicle = FakeVehicle()
    out = io.StringIO()
    console = Console([vehicle], stream_in=io.StringIO(""), stream_out=out)
    console.pump()
    vehicle.report(Severity.CRITICAL, "commander", "Failsafe activated")
    console.pump()
    console.pump()  # nothing new: prints nothing
    assert out.getvalue() == PROMPT + "\nERROR [commander] Failsafe activated\n" + PROMPT


def test_eof_ends_quietly_without_more_prompts():
    vehicle = FakeVehicle()
    console, out = _run(vehicle, "")
    before = out.getvalue()
    vehicle.report(Severity.INFO, "commander", "Takeoff detected")
    console.pump()
    assert out.getvalue() == before + "INFO  [commander] Takeoff detected\n"
    assert PROMPT not in out.getvalue()


def test_shutdown_command_calls_back_and_shows_no_prompt():
    calls = []
    out = io.StringIO()
    console = Console([FakeVehicle()], lambda: calls.append(True), stream_in=io.StringIO(""), stream_out=out)
    console._lines.put("shutdown")
    console.pump()
    assert calls == [True]
    assert out.getvalue() == "Exiting NOW.\n"


def test_closed_output_does_not_break_the_loop():
    vehicle = FakeVehicle()
    out = io.StringIO()
    console = Console([vehicle], stream_in=io.StringIO(""), stream_out=out)
    out.close()
    vehicle.report(Severity.INFO, "commander", "Armed by internal command")
    console.pump()  # must not raise
    console.stop()


def _console(vehicles: list[FakeVehicle]) -> tuple[Console, io.StringIO]:
    out = io.StringIO()
    return Console(vehicles, stream_in=io.StringIO(""), stream_out=out), out


def test_with_several_vehicles_the_console_says_which_it_controls():
    console, out = _console([FakeVehicle(sysid=s) for s in (1, 2, 3)])
    console.pump()
    assert out.getvalue() == ("INFO  [vehicle] console controls sysid 1 (vehicle 1 of 3, sysids 1-3); "
                              "'vehicle <sysid>' switches\n" + PROMPT)


def test_one_vehicle_needs_no_word_about_it():
    console, out = _console([FakeVehicle()])
    console.pump()
    assert out.getvalue() == PROMPT


def test_vehicle_command_switches_commands_and_log_lines_to_another_vehicle():
    vehicles = [FakeVehicle(sysid=s) for s in (1, 2, 3)]
    vehicles[1].report(Severity.INFO, "commander", "history of vehicle 2")
    console, out = _console(vehicles)
    console.pump()
    console._lines.put("vehicle 2")
    console._lines.put("commander arm")
    console.pump()
    assert "INFO  [vehicle] console controls sysid 2\n" in out.getvalue()
    assert [c.command for c in vehicles[1].commands] == [400] and vehicles[0].commands == []
    assert all(c.source_system == 2 for c in vehicles[1].commands)
    assert "history of vehicle 2" not in out.getvalue()  # its log from now on, not its past
    vehicles[1].report(Severity.INFO, "commander", "Armed by internal command")
    vehicles[0].report(Severity.INFO, "commander", "not the console's vehicle")
    console.pump()
    assert "Armed by internal command" in out.getvalue() and "not the console's vehicle" not in out.getvalue()


def test_vehicle_lists_and_refuses_an_unknown_sysid():
    console, out = _console([FakeVehicle(sysid=s) for s in (1, 2, 3)])
    console._lines.put("vehicle")
    console._lines.put("vehicle 9")
    console.pump()
    text = out.getvalue()
    assert "INFO  [vehicle] console controls sysid 1; vehicles (sysid): 1-3\n" in text
    assert "ERROR [vehicle] no vehicle with sysid 9; use one of 1-3\nCommand 'vehicle' failed, returned 1.\n" in text
    assert console.vehicle.sysid == 1


def test_help_on_the_console_lists_vehicle_and_listener():
    console, out = _console([FakeVehicle()])
    console._lines.put("help")
    console.pump()
    assert "  listener\n" in out.getvalue() and "  vehicle\n" in out.getvalue()


def test_listener_n_prints_as_published_and_the_prompt_comes_after():
    vehicle = FakeVehicle()
    console, out = _console([vehicle])
    console.pump()
    console._lines.put("listener vehicle_status -n 2")
    console.pump()
    assert "#1" in out.getvalue() and not out.getvalue().endswith(PROMPT)
    vehicle.time_us = 500_000
    console.pump()
    assert "#2" in out.getvalue() and out.getvalue().endswith(PROMPT)


def test_a_line_typed_while_listener_runs_stops_it():
    vehicle = FakeVehicle()
    console, out = _console([vehicle])
    console._lines.put("listener vehicle_status -n 5")
    console.pump()
    console._lines.put("")
    console.pump()
    vehicle.time_us = 500_000
    console.pump()
    assert "#2" not in out.getvalue() and out.getvalue().endswith(PROMPT)


class _FakeReadline(types.SimpleNamespace):
    """The calls ReadlineInput makes on the readline module, recorded."""

    def __init__(self) -> None:
        super().__init__(history=[], hook=None, completer=None, __doc__="GNU readline")

    def set_completer(self, f): self.completer = f
    def set_completer_delims(self, d): pass
    def parse_and_bind(self, s): self.binding = s
    def clear_history(self): self.history.clear()
    def add_history(self, line): self.history.append(line)
    def set_pre_input_hook(self, f): self.hook = f
    def get_begidx(self): return 0
    def get_line_buffer(self): return "commander ar"


def test_a_terminal_console_reads_through_readline(monkeypatch):
    fake = _FakeReadline()
    monkeypatch.setattr(terminal, "_both_ttys", lambda: True)
    monkeypatch.setattr(terminal, "_import_readline", lambda: fake)
    monkeypatch.setattr(terminal, "is_foreground", lambda fd: True)
    monkeypatch.setattr(sys.stdin, "fileno", lambda: 0, raising=False)
    reader = make_input(sys.stdin, sys.stdout, ["commander", "listener"], threading.Event())
    assert isinstance(reader, ReadlineInput) and reader.draws_prompt
    assert fake.history == ["commander takeoff"]  # as pxh, for convenience
    assert fake.binding == "tab: complete"
    assert [fake.completer("li", i) for i in range(2)] == ["listener ", None]
    prompts = []

    def fake_input(prompt):
        prompts.append(prompt)
        fake.hook()  # readline calls it once the prompt shows
        assert reader.at_prompt
        return "commander status"
    monkeypatch.setattr("builtins.input", fake_input)
    assert reader.read_line() == "commander status"
    assert prompts == [PROMPT] and not reader.at_prompt


def test_without_readline_the_terminal_is_read_line_by_line(monkeypatch):
    monkeypatch.setattr(terminal, "_both_ttys", lambda: True)
    monkeypatch.setitem(sys.modules, "readline", None)  # import readline fails, as where it does not exist
    reader = make_input(sys.stdin, sys.stdout, ["ver"], threading.Event())
    assert isinstance(reader, StreamInput) and not reader.draws_prompt


def test_other_streams_never_use_readline(monkeypatch):
    monkeypatch.setattr(terminal, "_both_ttys", lambda: True)
    reader = make_input(io.StringIO("ver\n"), io.StringIO(), ["ver"], threading.Event())
    assert isinstance(reader, StreamInput)
    assert reader.read_line() == "ver" and reader.read_line() is None


@pytest.mark.parametrize("at_prompt", [True, False])
def test_log_lines_go_above_the_readline_prompt(monkeypatch, at_prompt):
    fake = _FakeReadline()
    monkeypatch.setattr(terminal, "_both_ttys", lambda: True)
    monkeypatch.setattr(terminal, "_import_readline", lambda: fake)
    monkeypatch.setattr(terminal, "is_foreground", lambda fd: True)
    monkeypatch.setattr(sys.stdin, "fileno", lambda: 0, raising=False)
    out = io.StringIO()
    monkeypatch.setattr(sys, "stdout", out)
    monkeypatch.setattr(out, "isatty", lambda: True)
    vehicle = FakeVehicle()
    console = Console([vehicle], stream_in=sys.stdin, stream_out=sys.stdout)
    console._input.at_prompt = at_prompt
    vehicle.report(Severity.INFO, "commander", "Takeoff detected")
    console.pump()
    if at_prompt:  # clear the prompt line, print, draw the prompt and the text being typed again
        assert out.getvalue() == "\r\x1b[KINFO  [commander] Takeoff detected\n" + PROMPT + "commander ar"
    else:  # readline is about to draw the prompt itself
        assert out.getvalue() == "INFO  [commander] Takeoff detected\n"
    assert console._idle.is_set()  # the reader thread may show the prompt
