"""Byte transports for joyfly's MAVLink link: UDP (MAVROS fcu_url style or pymavlink udpin/udpout), any other
pymavlink connection string (tcp:, serial devices), and an in-memory pair for tests.

URL forms accepted by `open_transport`:
- `udp://[bind_host]:bind_port@[remote_host][:remote_port]` (MAVROS fcu_url; default udp://:14540@127.0.0.1:14557)
- `udpin:host:port` (listen), `udpout:host:port` / `udp:host:port` (send first), as pymavlink spells them
- `tcp:host:port`, `tcp://host:port`, `/dev/ttyACM0[:baud]`, `serial:///dev/ttyUSB0:57600`: through pymavlink.

Like MAVROS's mavconn (libmavconn/src/udp.cpp), the UDP transport sends to the given remote until the vehicle
talks, then answers whoever sent the last datagram (PX4 SITL binds 14580 today; old docs say 14557).
"""

from __future__ import annotations

import collections
import contextlib
import errno
import select
import socket
from typing import Any, Protocol


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

    def close(self) -> None:
        self._sock.close()


class MavutilTransport:
    """Any pymavlink connection (tcp, serial, ...), used only for its raw bytes."""

    def __init__(self, spec: str) -> None:
        from pymavlink import mavutil

        try:
            self._conn: Any = mavutil.mavlink_connection(spec, source_system=255, source_component=190)
        except Exception as exc:  # pymavlink raises bare exceptions for bad devices / refused TCP
            raise TransportError(f"Cannot open {spec!r}: {exc}.") from None
        self.description = spec

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


class MemoryTransport:
    """One end of an in-memory pair: what one end writes, the other reads. Never waits (simulated time)."""

    def __init__(self, description: str = "memory") -> None:
        self.description = description
        self.inbox: collections.deque[bytes] = collections.deque()
        self.peer: MemoryTransport | None = None
        self.closed = False

    def write(self, data: bytes) -> None:
        if self.peer is not None and not self.closed:
            self.peer.inbox.append(bytes(data))

    def read(self, timeout_s: float) -> bytes:
        return self.inbox.popleft() if self.inbox else b""

    def close(self) -> None:
        self.closed = True


def memory_pair() -> tuple[MemoryTransport, MemoryTransport]:
    a, b = MemoryTransport("memory:a"), MemoryTransport("memory:b")
    a.peer, b.peer = b, a
    return a, b


def _host_port(text: str, default_host: str, what: str) -> tuple[str, int]:
    host, sep, port = text.rpartition(":")
    if not sep:
        host, port = text, ""
    try:
        return host or default_host, int(port)
    except ValueError:
        raise TransportError(f"Bad {what} {text!r} in the connection URL: expected host:port.") from None


def parse_udp_url(url: str) -> tuple[tuple[str, int], tuple[str, int] | None]:
    """`udp://[bind_host]:bind_port@[remote_host][:remote_port]` -> (bind address, remote address or None)."""
    body = url[len("udp://"):].split("/?", 1)[0]  # MAVROS's "/?ids=sysid,compid" names MAVROS itself: ignored
    local, _, remote = body.partition("@")
    bind = _host_port(local, "0.0.0.0", "listen address")
    if not remote:
        return bind, None
    if ":" not in remote:
        remote += ":14555"  # mavconn's default remote port
    return bind, _host_port(remote, "127.0.0.1", "vehicle address")


def open_transport(url: str) -> Transport:
    """Open the transport a connection URL names (see the module docstring)."""
    if url.startswith("udp://"):
        bind, remote = parse_udp_url(url)
        return UdpTransport(bind, remote)
    if url.startswith("udpin:"):
        return UdpTransport(_host_port(url[len("udpin:"):], "0.0.0.0", "listen address"), None)
    for prefix in ("udpout:", "udp:"):
        if url.startswith(prefix):
            return UdpTransport(("0.0.0.0", 0), _host_port(url[len(prefix):], "127.0.0.1", "vehicle address"))
    if url.startswith("tcp://"):
        return MavutilTransport("tcp:" + url[len("tcp://"):])
    if url.startswith("serial://"):
        return MavutilTransport(_serial_spec(url[len("serial://"):]))
    if url.startswith(("tcp:", "tcpin:", "/dev/", "COM")):
        return MavutilTransport(url)
    raise TransportError(
        f"Unknown connection URL {url!r}: use udp://:14540@127.0.0.1:14557, udpin:0.0.0.0:14540, tcp:host:port "
        "or a serial device."
    )


def _serial_spec(path_baud: str) -> str:
    """MAVROS `serial:///dev/ttyUSB0:57600` -> pymavlink `/dev/ttyUSB0,57600`."""
    path, sep, baud = path_baud.rpartition(":")
    return f"{path},{baud}" if sep and baud.isdigit() else path_baud
