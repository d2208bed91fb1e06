"""What a user types to `sitl-emu`, checked before anything opens, and the one style of every user error.

Every mistake ends as one line on stderr, `sitl-emu: <what is wrong and what to do>`, with a non-zero exit status and
no traceback: click's own usage errors too (`OneLineGroup` turns them into `UserError`). Range errors name the range.
joyfly/cli_style.py is its twin for `joyfly` (joyfly imports sitl_emu only to run the demo's emulator, and
sitl_emu never imports joyfly: ARCHITECTURE.md); change both.
"""

from __future__ import annotations

import importlib.metadata
import math
import socket
from collections.abc import Sequence
from typing import IO, TYPE_CHECKING, Any

import click

if TYPE_CHECKING:
    from sitl_emu.runtime.node import LinkSettings

TOOL = "sitl-emu"
PORT_MAX = 65535
# --speed: simulated seconds per wall second. joyfly's --speed takes the same range (joyfly/config.py; a test keeps
# them equal): below 0.1 nothing is worth watching, above 100 neither the emulator (about 90 simulated s per CPU s
# with its I/O, README) nor a client keeps up.
SPEED_MIN, SPEED_MAX = 0.1, 100.0
SEED_MAX = 2**32 - 1  # numpy takes any non-negative integer; 32 bits are plenty
MAX_SYSID = 251  # --instance 250 is the last: system id 251
CONTEXT = {"help_option_names": ["-h", "--help"]}


class UsageProblem(Exception):
    """A user mistake; str(err) is one sentence."""


class UserError(click.ClickException):
    """A mistake the user can fix, shown as one line `sitl-emu: sentence` on stderr; exit status 2."""

    exit_code = 2

    def show(self, file: IO[Any] | None = None) -> None:
        click.echo(f"{TOOL}: {self.message}", err=True)


class UserFailure(UserError):
    """The same with exit status 1 (click.ClickException's status: a command that could not do its work)."""

    exit_code = 1


def one_line(err: click.ClickException) -> UserError:
    """click's error as a UserError with its exit status; a usage error says where the help is."""
    text = " ".join(err.format_message().split())
    ctx = getattr(err, "ctx", None)
    if isinstance(err, click.UsageError) and ctx is not None:
        hint = f"see '{ctx.command_path} --help'"
        text = f"{text} ({hint})" if text.endswith("?") else f"{text.rstrip('.')} ({hint})."
    return UserFailure(text) if err.exit_code == 1 else UserError(text)


VERSION_MESSAGE = "%(prog)s %(version)s (the joyfly package)"  # what --version prints, on the tool and its commands


def _show_version(ctx: click.Context, param: click.Parameter, value: bool) -> None:
    if value and not ctx.resilient_parsing:
        click.echo(VERSION_MESSAGE % {"prog": TOOL, "version": importlib.metadata.version("joyfly")})
        ctx.exit()


def version_option() -> click.Option:
    """--version as on the tool itself, for one of its commands."""
    return click.Option(["--version"], is_flag=True, expose_value=False, is_eager=True, callback=_show_version,
                        help="Show the version and exit.")


class OneLineGroup(click.Group):
    """A click group whose errors, click's usage errors included, are one line (`UserError`); each command added to
    it takes --version too, as the tool does."""

    def add_command(self, cmd: click.Command, name: str | None = None) -> None:
        if not any("--version" in param.opts for param in cmd.params):
            cmd.params.append(version_option())
        super().add_command(cmd, name)

    def make_context(self, info_name: str | None, args: list[str], parent: click.Context | None = None,
                     **extra: Any) -> click.Context:
        try:
            return super().make_context(info_name, args, parent, **extra)
        except UserError:
            raise
        except click.ClickException as err:
            raise one_line(err) from None

    def invoke(self, ctx: click.Context) -> Any:
        try:
            return super().invoke(ctx)
        except UserError:
            raise
        except click.ClickException as err:
            raise one_line(err) from None


class WholeRange(click.IntRange):
    """click.IntRange that calls its values whole numbers ("not a valid integer", not "integer range")."""

    name = "integer"


class FiniteRange(click.FloatRange):
    """click.FloatRange that also refuses nan (nan compares false with both bounds, so FloatRange lets it through)."""

    name = "float"

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        number = super().convert(value, param, ctx)
        if not math.isfinite(number):
            self.fail(f"{value!r} is not a number from {self.min:g} to {self.max:g}.", param, ctx)
        return number


def check_host(host: str, what: str) -> None:
    try:
        socket.getaddrinfo(host, None, socket.AF_INET)
    except (socket.gaierror, UnicodeError):
        raise UsageProblem(f"{what}: no such host '{host}'; use an IP address such as 127.0.0.1 or a name this "
                           "machine resolves.") from None


def parse_address(text: str, what: str) -> tuple[str, int]:
    host, sep, port = text.rpartition(":")
    if not sep or not host or not port.isdigit():
        raise UsageProblem(f"{what} must look like HOST:PORT (for example 127.0.0.1:14540), not '{text}'.")
    if not 1 <= int(port) <= PORT_MAX:
        raise UsageProblem(f"{what} {text}: port {int(port)} is out of range; use a port from 1 to {PORT_MAX}.")
    check_host(host, what)
    return host, int(port)


def parse_home(text: str) -> tuple[float, float, float]:
    try:
        lat, lon, alt = (float(p) for p in text.split(","))
    except ValueError:
        raise UsageProblem(f"--home must be LAT,LON,ALT in degrees and metres AMSL, not '{text}'.") from None
    if not (-90 <= lat <= 90 and -180 <= lon <= 180 and -500 <= alt <= 9000):
        raise UsageProblem(f"--home {text} is out of range (latitude ±90, longitude ±180, altitude -500..9000 m).")
    return lat, lon, alt


THIS_MACHINE = frozenset({"127.0.0.1", "localhost", "0.0.0.0", "::1"})


def check_own_ports(links: Sequence[LinkSettings]) -> None:
    """`links`: every vehicle's (after LinkSettings.for_instance). No two links listen on one port, and no link sends
    to a port they listen on: it would latch onto itself and talk to itself."""
    listening: dict[int, str] = {}
    for s in links:
        for option, port in (("--port", s.api_port), ("--gcs-port", s.gcs_port)):
            if not port:  # 0: any free port
                continue
            if port in listening:
                raise UsageProblem(f"{listening[port]} and {option} give two links port {port} (with --count, "
                                   "vehicle N listens on each port + N): choose ports further apart.")
            listening[port] = option
    for s in links:
        for option, (host, port) in (("--remote", s.api_remote), ("--gcs-remote", s.gcs_remote)):
            if port in listening and (host in THIS_MACHINE or host == s.bind_host):
                raise UsageProblem(f"{option} {host}:{port} is a port this emulator listens on ({listening[port]}): "
                                   "it would talk to itself; point it at the client (PX4 SITL sends the API link "
                                   "to 14540, the ground station's to 14550).")


def check_instances(instance: int, count: int, ports: dict[str, int], api_remote_port: int) -> None:
    """Every vehicle's system id and offset ports exist (PX4's -i N offsets ports by N; the API remote only for
    N <= 9: server.LinkSettings.for_instance)."""
    last = instance + count - 1
    if last + 1 > MAX_SYSID:
        raise UsageProblem(f"--instance {instance} with --count {count} needs system ids up to {last + 1}; keep "
                           f"--instance + --count at most {MAX_SYSID}.")
    for option, port in ports.items():
        if port and port + last > PORT_MAX:
            raise UsageProblem(f"{option} {port} offset by instance {last} is port {port + last}, above {PORT_MAX}; "
                               f"use {option} at most {PORT_MAX - last} or fewer vehicles.")
    offset = min(last, 9) if instance <= 9 else 0
    if api_remote_port + offset > PORT_MAX:
        raise UsageProblem(f"--remote port {api_remote_port} offset by instance {offset} is above {PORT_MAX}; use a "
                           f"--remote port at most {PORT_MAX - offset}.")
