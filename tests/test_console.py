"""The terminal console: lines from stdin run as pxh> commands; vehicle events print as PX4 log lines."""

from __future__ import annotations

import io

from handler_ctx import FakeVehicle

from sitl_emu.console import PROMPT, Console
from sitl_emu.px4 import Severity


def _run(vehicle: FakeVehicle, text: str, on_shutdown=None) -> tuple[Console, io.StringIO]:
    out = io.StringIO()
    console = Console(vehicle, on_shutdown, stream_in=io.StringIO(text), stream_out=out)
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


def test_boot_events_then_prompt():
    vehicle = FakeVehicle()
    vehicle.report(Severity.INFO, "commander", "Ready for takeoff!")
    out = io.StringIO()
    console = Console(vehicle, stream_in=io.StringIO(""), stream_out=out)
    console.pump()  # before the reader has seen EOF: shows the log and a prompt
    assert out.getvalue() == "INFO  [commander] Ready for takeoff!\n" + PROMPT


def test_output_of_each_command_then_prompt():
    vehicle = FakeVehicle()
    out = io.StringIO()
    console = Console(vehicle, stream_in=io.StringIO(""), stream_out=out)
    console.pump()
    console._lines.put("param get MAV_SYS_ID")
    console._lines.put("nonsense")
    console.pump()
    assert out.getvalue() == (PROMPT + "1\n" + "Invalid command: nonsense\ntype 'help' for a list of commands\n"
                              + PROMPT)


def test_events_arriving_later_are_printed_on_their_own_line():
    vehicle = FakeVehicle()
    out = io.StringIO()
    console = Console(vehicle, stream_in=io.StringIO(""), stream_out=out)
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
    console = Console(FakeVehicle(), lambda: calls.append(True), stream_in=io.StringIO(""), stream_out=out)
    console._lines.put("shutdown")
    console.pump()
    assert calls == [True]
    assert out.getvalue() == "Exiting NOW.\n"


def test_closed_output_does_not_break_the_loop():
    vehicle = FakeVehicle()
    out = io.StringIO()
    console = Console(vehicle, stream_in=io.StringIO(""), stream_out=out)
    out.close()
    vehicle.report(Severity.INFO, "commander", "Armed by internal command")
    console.pump()  # must not raise
    console.stop()
