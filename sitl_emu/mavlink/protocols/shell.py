"""The MAVLink shell: SERIAL_CONTROL device 10 to the pxh> shell and back (px4-behaviour.md section 8).

Receive (mavlink_receiver.cpp handle_message_serial_control): ignore messages for another system/component, with the
REPLY flag, or for another device than SHELL (10). The first accepted message opens the shell. 0 < count <= 70 data
bytes are written to it and the sender becomes the reply target. Without the RESPOND flag the shell is closed after
the write (a message with flags 0 ends the session).
Shell (pxh.cpp run_remote_pxh): no prompt on start; every input byte > 3 is echoed; on '\\n' it prints "\\n", runs
the line, then prints the prompt "pxh> ". Log output (vehicle events) shows up in the session while it is open.
A command that keeps printing (`listener -n N`) runs to its end before the prompt, as process_line() blocks in PX4;
bytes that arrive meanwhile wait and are handled after it, as they wait in the shell's input pipe in PX4.
Output (mavlink_main.cpp handleMavlinkShellOutput): SERIAL_CONTROL {device 10, flags REPLY, timeout 0, baudrate 0,
count <= 70}. PX4 sends one chunk per 1.5 ms main-loop pass; we send up to CHUNKS_PER_TICK per tick so long outputs
(`param show`) arrive as quickly.
The target_system/target_component extension fields are not in pymavlink's dialects: incoming ones read as 0
(accepted) and outgoing replies carry 0 (clients match on device and the REPLY flag, not on the target).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, ClassVar, cast

from sitl_emu.console.shell import Shell
from sitl_emu.mavlink.wire.fastpack import ENCODER

if TYPE_CHECKING:
    from pymavlink.dialects.v20.development import MAVLink_message, MAVLink_serial_control_message

    from sitl_emu.mavlink.context import LinkContext, LinkVehicle

SERIAL_CONTROL_DEV_SHELL = 10
SERIAL_CONTROL_FLAG_REPLY = 1
SERIAL_CONTROL_FLAG_RESPOND = 2
MAX_CHUNK = 70
CHUNKS_PER_TICK = 8
MAX_LINE = 1024  # longer input lines are cut (a client streaming bytes without a newline must not grow memory)
MAX_PENDING_OUTPUT = 64 * 1024  # a vanished client must not make the buffer grow forever
PROMPT = b"pxh> "


class ShellBridge:
    """One instance per link: at most one shell session, as PX4 has one MavlinkShell per Mavlink instance."""

    MESSAGES: ClassVar[tuple[str, ...]] = ("SERIAL_CONTROL",)

    def __init__(self, *, on_shutdown: Callable[[], None] | None = None) -> None:
        self._on_shutdown = on_shutdown
        self._shell: Shell | None = None
        self._line = bytearray()
        self._out = bytearray()
        self._waiting_input = bytearray()  # arrived while a command still runs
        self._last_seq = -1

    @property
    def is_open(self) -> bool:
        return self._shell is not None

    # --- receive -----------------------------------------------------------------------------------------------
    def handle(self, msg: MAVLink_message, ctx: LinkContext) -> None:
        msg = cast("MAVLink_serial_control_message", msg)  # MESSAGES: the endpoint sends only SERIAL_CONTROL
        if not _accepted(msg, ctx):
            return
        if self._shell is None:
            self._open(ctx)
        if 0 < msg.count <= MAX_CHUNK:
            self._write(bytes(msg.data[: msg.count]), ctx)
        if not msg.flags & SERIAL_CONTROL_FLAG_RESPOND:
            self._close()

    def _open(self, ctx: LinkContext) -> None:
        self._shell = Shell(ctx.vehicle, self._on_shutdown)
        self._line.clear()
        self._out.clear()
        self._last_seq = _latest_event_seq(ctx.vehicle)  # show log lines from now on, not the boot log

    def _close(self) -> None:
        self._shell = None
        self._line.clear()
        self._out.clear()
        self._waiting_input.clear()

    def _write(self, data: bytes, ctx: LinkContext) -> None:
        for i, byte in enumerate(data):
            if self._shell is not None and self._shell.busy:
                self._waiting_input += data[i:][: max(0, MAX_LINE - len(self._waiting_input))]
                return
            if byte == 0x0A:
                self._run_line(ctx)
            elif byte > 3 and len(self._line) < MAX_LINE:
                self._out.append(byte)  # echo
                self._line.append(byte)

    def _run_line(self, ctx: LinkContext) -> None:
        assert self._shell is not None
        line = self._line.decode("utf-8", errors="replace")
        self._line.clear()
        self._out += b"\n"
        self._collect_events(ctx)
        self._out += self._shell.execute(line).encode("utf-8", errors="replace")
        self._collect_events(ctx)
        if not self._shell.busy:
            self._out += PROMPT

    # --- transmit ----------------------------------------------------------------------------------------------
    def tick(self, ctx: LinkContext) -> bool:
        """The shell's output and events; False until a SERIAL_CONTROL has opened the shell."""
        if self._shell is None:
            return False
        self._collect_events(ctx)
        if self._shell.busy:
            self._continue_command(ctx)
        for _ in range(CHUNKS_PER_TICK):
            if not self._out:
                break
            chunk = bytes(self._out[:MAX_CHUNK])
            del self._out[:MAX_CHUNK]
            data = list(chunk) + [0] * (MAX_CHUNK - len(chunk))
            ctx.send(ENCODER.serial_control_encode(SERIAL_CONTROL_DEV_SHELL, SERIAL_CONTROL_FLAG_REPLY, 0, 0,
                                                   len(chunk), data))
        return True

    def _continue_command(self, ctx: LinkContext) -> None:
        """Output of the running command; when it has ended, the prompt and then the input that waited for it."""
        assert self._shell is not None
        self._out += self._shell.poll().encode("utf-8", errors="replace")
        if not self._shell.busy:
            self._out += PROMPT
            waiting = bytes(self._waiting_input)
            self._waiting_input.clear()
            self._write(waiting, ctx)

    def _collect_events(self, ctx: LinkContext) -> None:
        events = ctx.vehicle.events_after(self._last_seq)
        if events:
            self._last_seq = events[-1].seq
            self._out += "".join(e.console_line + "\n" for e in events).encode("utf-8", errors="replace")
        if len(self._out) > MAX_PENDING_OUTPUT:
            del self._out[: len(self._out) - MAX_PENDING_OUTPUT]


def _accepted(msg: MAVLink_serial_control_message, ctx: LinkContext) -> bool:
    target_system = getattr(msg, "target_system", 0)
    target_component = getattr(msg, "target_component", 0)
    if target_system not in (0, ctx.sysid) or target_component not in (0, ctx.compid):
        return False
    return not msg.flags & SERIAL_CONTROL_FLAG_REPLY and msg.device == SERIAL_CONTROL_DEV_SHELL


def _latest_event_seq(vehicle: LinkVehicle) -> int:
    events = vehicle.events_after(-1)
    return events[-1].seq if events else -1
