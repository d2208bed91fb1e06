"""Byte transports for joyfly's MAVLink link: UDP (MAVROS fcu_url style or pymavlink udpin/udpout), any other
pymavlink connection string (tcp:, serial devices), and an in-memory pair for tests.

URL forms accepted by `open_transport`:
- `udp://[bind_host]:bind_port@[remote_host][:remote_port]` (MAVROS fcu_url; default udp://:14540@127.0.0.1:14557)
- `udpin:host:port` (listen), `udpout:host:port` / `udp:host:port` (send first), as pymavlink spells them
- `tcp:host:port`, `tcp://host:port`, `/dev/ttyACM0[:baud]`, `serial:///dev/ttyUSB0:57600`: through pymavlink
  (serial devices through pyserial, as pymavlink opens them).
`parse_url` checks a URL without opening anything: ports 1-65535; a UDP listen port may be 0 (any free port, named
in joyfly's first line).

Like MAVROS's mavconn (libmavconn/src/udp.cpp), the UDP transport sends to the given remote until the vehicle
talks, then answers whoever sent the last datagram (PX4 SITL binds 14580 today; old docs say 14557).
"""

from __future__ import annotations

import contextlib
import errno
import io
import os
import select
import socket
from dataclasses import dataclass
from typing import Any, Protocol

PORT_MAX = 65535
DEFAULT_BAUD = 115200  # pymavlink's default; USB (ttyACM) links ignore it
BAUD_MIN, BAUD_MAX = 50, 4_000_000  # Linux termios: B50 .. B4000000


class TransportError(Exception):
    """A connection problem the user can fix; the message is one sentence saying what to do."""


class Transport(Protocol):
    description: str  # where we listen / send, for messages like "no heartbeat on udp 0.0.0.0:14540"

    def write(self, data: bytes) -> None: ...

    def read(self, timeout_s: float) -> bytes:
        """Return the bytes that arrived (waiting at most timeout_s), or b"" if none."""
        ...

    def close(self) -> None: ...


class UdpTransport:
    def __init__(self, bind: tuple[str, int], remote: tuple[str, int] | None) -> None:
        self._sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            self._sock.bind(bind)
        except OSError as exc:
            self._sock.close()
            if exc.errno == errno.EADDRINUSE:
                raise TransportError(
                    f"UDP port {bind[1]} is already in use (another joyfly, MAVROS or MAVSDK program?): "
                    "stop it or pick another port with --url."
                ) from None
            raise TransportError(f"Cannot listen on UDP {bind[0] or '0.0.0.0'}:{bind[1]} ({exc.strerror}).") from None
        self._sock.setblocking(False)
        self.remote = remote
        host, port = self._sock.getsockname()
        self.local_port: int = port
        target = f", sending to {remote[0]}:{remote[1]}" if remote else ""
        self.description = f"UDP {host}:{port}{target}"

    def write(self, data: bytes) -> None:
        if self.remote is None:
            return  # nobody to talk to until the vehicle's first datagram
        # ICMP unreachable and friends are ignored: the heartbeat watchdog reports a dead link
        with contextlib.suppress(OSError):
            self._sock.sendto(data, self.remote)

    def read(self, timeout_s: float) -> bytes:
        if timeout_s > 0:
            ready, _, _ = select.select([self._sock], [], [], timeout_s)
            if not ready:
                return b""
        try:
            data, addr = self._sock.recvfrom(65535)
        except (BlockingIOError, InterruptedError, ConnectionRefusedError):
            return b""
        self.remote = addr
        return data

    def vehicle_port_taken(self) -> bool | None:
        """Whether a program on this machine holds the UDP port joyfly sends to (binding it fails: EADDRINUSE), so a
        vehicle that stays silent there is alive but talks to another client; None when that address is not this
        machine's (EADDRNOTAVAIL) or there is none yet: joyfly cannot tell."""
        if self.remote is None:
            return None
        probe = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            probe.bind(self.remote)
        except OSError as exc:
            return True if exc.errno == errno.EADDRINUSE else None
        finally:
            probe.close()
        return False

    def close(self) -> None:
        self._sock.close()


class MavutilTransport:
    """Any pymavlink connection (tcp, serial, ...), used only for its raw bytes."""

    def __init__(self, spec: str, conn: Any = None, description: str = "") -> None:
        if conn is None:
            from pymavlink import mavutil

            try:  # pymavlink prints each refused TCP attempt ("... sleeping"): the one sentence below says it
                with contextlib.redirect_stdout(io.StringIO()):
                    conn = mavutil.mavlink_connection(spec, source_system=255, source_component=190)
            except Exception as exc:  # pymavlink raises bare exceptions for refused TCP and the like
                raise TransportError(f"Cannot open {spec!r} ({exc}): is the vehicle listening there?") from None
        self._conn: Any = conn
        self.description = description or spec

    def write(self, data: bytes) -> None:
        self._conn.write(data)

    def read(self, timeout_s: float) -> bytes:
        fd = getattr(self._conn, "fd", None)
        if fd is not None and timeout_s > 0:
            ready, _, _ = select.select([fd], [], [], timeout_s)
            if not ready:
                return b""
        data = self._conn.recv()
        return bytes(data) if data else b""

    def close(self) -> None:
        self._conn.close()


@dataclass(frozen=True, slots=True)
class Endpoint:
    """What a connection URL names: UDP (a listen and/or a vehicle address), TCP or a serial device."""

    kind: str  # "udp" | "tcp" | "serial"
    bind: tuple[str, int] | None = None
    remote: tuple[str, int] | None = None
    spec: str = ""  # tcp: pymavlink's connection string; serial: the device
    baud: int = 0


class UrlError(TransportError):
    """A connection URL that cannot be right; `detail` says which part and what to write instead."""

    def __init__(self, url: str, detail: str) -> None:
        super().__init__(f"Bad connection URL '{url}': {detail}.")
        self.detail = detail


def _host_port(url: str, text: str, default_host: str, what: str, lowest: int) -> tuple[str, int]:
    host, sep, port = text.rpartition(":")
    if not sep:
        host, port = text, ""
    if not port.isdigit():
        raise UrlError(url, f"the {what} address '{text}' is not HOST:PORT")
    if not lowest <= int(port) <= PORT_MAX:
        anyport = " (0: any free port)" if lowest == 0 else ""
        raise UrlError(url, f"the {what} port {int(port)} is out of range; use {lowest} to {PORT_MAX}{anyport}")
    return host or default_host, int(port)


def parse_udp_url(url: str) -> tuple[tuple[str, int], tuple[str, int] | None]:
    """`udp://[bind_host]:bind_port@[remote_host][:remote_port]` -> (bind address, remote address or None)."""
    body = url[len("udp://"):].split("/?", 1)[0]  # MAVROS's "/?ids=sysid,compid" names MAVROS itself: ignored
    local, _, remote = body.partition("@")
    bind = _host_port(url, local, "0.0.0.0", "listen", 0)
    if not remote:
        return bind, None
    if ":" not in remote:
        remote += ":14555"  # mavconn's default remote port
    return bind, _host_port(url, remote, "127.0.0.1", "vehicle", 1)


def parse_url(url: str) -> Endpoint:
    """The endpoint a connection URL names (see the module docstring), checked; nothing is opened."""
    if url.startswith("udp://"):
        bind, remote = parse_udp_url(url)
        return Endpoint("udp", bind, remote)
    if url.startswith("udpin:"):
        return Endpoint("udp", _host_port(url, url[len("udpin:"):], "0.0.0.0", "listen", 0))
    for prefix in ("udpout:", "udp:"):
        if url.startswith(prefix):
            return Endpoint("udp", ("0.0.0.0", 0), _host_port(url, url[len(prefix):], "127.0.0.1", "vehicle", 1))
    for prefix, spec in (("tcp://", "tcp:"), ("tcp:", "tcp:"), ("tcpin:", "tcpin:")):
        if url.startswith(prefix):
            host, port = _host_port(url, url[len(prefix):], "127.0.0.1", "TCP", 1)
            return Endpoint("tcp", spec=f"{spec}{host}:{port}")
    if url.startswith("serial://"):
        return _serial_endpoint(url, url[len("serial://"):])
    if url.startswith(("/dev/", "COM")):
        return _serial_endpoint(url, url)
    raise UrlError(url, "use udp://:14540@127.0.0.1:14557 (MAVROS style), udpin:0.0.0.0:14540, udpout:HOST:PORT, "
                        "tcp:HOST:PORT or a serial device such as /dev/ttyACM0:57600")


def _serial_endpoint(url: str, text: str) -> Endpoint:
    """`/dev/ttyUSB0`, `/dev/ttyUSB0:57600` (MAVROS) or `/dev/ttyUSB0,57600` (pymavlink); a path that exists as
    written (/dev/serial/by-path/... names hold colons) is the device itself."""
    for sep in (":", ","):
        path, found, baud = text.rpartition(sep)
        if found and path and baud.isdigit() and not os.path.exists(text):
            if not BAUD_MIN <= int(baud) <= BAUD_MAX:
                raise UrlError(url, f"the baud rate {baud} is out of range; use {BAUD_MIN} to {BAUD_MAX}, "
                                    "for example 57600 or 921600")
            return Endpoint("serial", spec=path, baud=int(baud))
    return Endpoint("serial", spec=text, baud=DEFAULT_BAUD)


def open_transport(url: str) -> Transport:
    """Open the transport a connection URL names (see the module docstring)."""
    endpoint = parse_url(url)
    if endpoint.kind == "udp":
        return UdpTransport(endpoint.bind or ("0.0.0.0", 0), _resolved(endpoint.remote))
    if endpoint.kind == "serial":
        return open_serial(endpoint.spec, endpoint.baud)
    return MavutilTransport(endpoint.spec)


def _resolved(remote: tuple[str, int] | None) -> tuple[str, int] | None:
    """The vehicle's address with its host name looked up once (sendto would look it up for every datagram)."""
    if remote is None:
        return None
    try:
        return socket.gethostbyname(remote[0]), remote[1]
    except (OSError, UnicodeError):
        raise TransportError(f"Unknown host '{remote[0]}' in --url: use an IP address such as 127.0.0.1, or a name "
                             "this machine resolves.") from None


def open_serial(device: str, baud: int) -> MavutilTransport:
    """A serial link through pymavlink (which uses pyserial); a missing or unusable device is one sentence."""
    from pymavlink import mavutil

    try:
        import serial  # noqa: F401  (pymavlink imports it too; here a missing pyserial is named)
    except ImportError:
        raise TransportError("Serial links need pyserial: pip install pyserial.") from None
    try:
        conn = mavutil.mavlink_connection(device, baud=baud, source_system=255, source_component=190)
    except (OSError, ValueError) as exc:  # serial.SerialException is an OSError; ValueError: a bad baud rate
        raise TransportError(_serial_problem(device, exc)) from None
    return MavutilTransport(device, conn, f"serial {device} at {baud} baud")


def _serial_problem(device: str, exc: Exception) -> str:
    code = getattr(exc, "errno", None)
    if code == errno.ENOENT:
        return (f"No serial device {device}: plug the autopilot in and check the name "
                "(ls /dev/ttyACM* /dev/ttyUSB*).")
    if code in (errno.EACCES, errno.EPERM):
        return (f"No permission to open {device}: add yourself to the dialout group "
                "(sudo usermod -aG dialout $USER, then log in again).")
    if code == errno.EBUSY:
        return f"{device} is busy: close the other program using it (a ground station, ModemManager?)."
    reason = getattr(exc, "strerror", None) or str(exc)
    return f"Cannot open the serial device {device} ({reason}): check that it is the autopilot's serial port."
