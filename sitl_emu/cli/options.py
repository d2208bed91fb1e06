"""What a user types to `sitl-emu`, checked before anything opens.

Every mistake ends as one line on stderr, `sitl-emu: <what is wrong and what to do>`, with a non-zero exit status and
no traceback, in the style both command lines share (px4common/cli_style.py: `UserError`, `OneLineGroup`). A check
here raises `UsageProblem` with one sentence; the command turns it into a `UserError`. Range errors name the range.
"""

from __future__ import annotations

import socket
from collections.abc import Sequence
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from sitl_emu.runtime.node import LinkSettings

TOOL = "sitl-emu"
PORT_MAX = 65535
SEED_MAX = 2**32 - 1  # numpy takes any non-negative integer; 32 bits are plenty
MAX_SYSID = 251  # --instance 250 is the last: system id 251
VERSION_MESSAGE = "%(prog)s %(version)s (the joyfly package)"  # what --version prints, on the tool and its commands


class UsageProblem(Exception):
    """A user mistake; str(err) is one sentence."""


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
        for option, remote in (("--remote", s.api_remote), ("--gcs-remote", s.gcs_remote)):
            if remote is None:  # no peer until one talks (a Sim's link): it sends nowhere
                continue
            host, port = remote
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
