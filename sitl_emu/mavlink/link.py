"""One UDP link end, as PX4's mavlink module opens it in SITL.

PX4 (src/modules/mavlink/mavlink_main.cpp init_udp / send_finish, mavlink_receiver.cpp) binds a local port, sends to
127.0.0.1:<remote port> from boot, and on the first datagram it receives latches that sender as its partner for good:
later senders are still parsed but never answered. This module does exactly that and nothing else: no parsing, no
clock. Sockets are non-blocking; `receive()` returns at most `max_datagrams` datagrams so a flood cannot starve the
physics loop (the kernel drops what does not fit its buffer, as it would for PX4).

An in-process Sim may open a link with no remote at all (`remote=None`: nobody could receive what it sent). Such a
link sends nothing, and its endpoint builds nothing to send, until the first datagram arrives; its sender is then
latched as PX4 latches it. `serve` always gives both links a remote, so its wire is PX4's.
"""

from __future__ import annotations

import errno
import logging
import socket
from collections.abc import Callable
from dataclasses import dataclass
from typing import Final

from sitl_emu.mavlink.link_errors import PortInUseError

log = logging.getLogger(__name__)

Address = tuple[str, int]
_MAX_DATAGRAM: Final = 65535
_RCVBUF_BYTES: Final = 1 << 20


@dataclass(slots=True)
class LinkStats:
    rx_datagrams: int = 0
    rx_bytes: int = 0
    tx_datagrams: int = 0
    tx_bytes: int = 0
    tx_errors: int = 0
    rx_ignored_foreign: int = 0  # datagrams from senders other than the latched peer (parsed, never answered)


class UdpLink:
    """A bound UDP socket with PX4's addressing: initial remote, then the first peer heard, forever.

    `remote` None: no peer until one talks (`has_peer` False); what would be sent meanwhile is dropped uncounted."""

    def __init__(self, bind_host: str, port: int, remote: Address | None, name: str = "link") -> None:
        self.name = name
        self.remote: Address | None = remote
        self.peer_latched = False
        self.stats = LinkStats()
        self._sock = _open_socket(bind_host, port, name)
        # bound once: the compiled send() then calls it directly, without looking the method up on the socket; the
        # address is passed as the object it is (typed Address, compiled code would unpack the tuple and build a new
        # one for every datagram)
        self._sendto: Callable[..., int] = self._sock.sendto
        self.local_address: Address = self._sock.getsockname()

    @property
    def port(self) -> int:
        return self.local_address[1]

    def fileno(self) -> int:
        return self._sock.fileno()

    def receive(self, max_datagrams: int = 256) -> list[bytes]:
        """Datagrams waiting now (never blocks). The first one's sender becomes the peer.

        Runners call this only for a socket their SocketWatch saw readable (sitl_emu/runtime/runner.py), so an idle link
        costs nothing here and this does not look again before reading."""
        out: list[bytes] = []
        while len(out) < max_datagrams:
            try:
                data, addr = self._sock.recvfrom(_MAX_DATAGRAM)
            except (BlockingIOError, InterruptedError):
                break
            except OSError as err:  # ICMP port unreachable from an earlier send, etc.: not fatal for UDP
                if err.errno in (errno.ECONNREFUSED, errno.EHOSTUNREACH, errno.ENETUNREACH, errno.ECONNRESET):
                    continue
                log.debug("%s: recvfrom failed: %s", self.name, err)
                break
            self._note_sender((addr[0], addr[1]))
            self.stats.rx_datagrams += 1
            self.stats.rx_bytes += len(data)
            out.append(data)
        return out

    @property
    def has_peer(self) -> bool:
        """True when a datagram sent now goes somewhere: a remote was given or a peer has talked."""
        return self.remote is not None

    def send(self, data: bytes) -> None:
        """Send to the peer (or the initial remote); a failed send is counted, never raised (UDP is lossy)."""
        remote: object = self.remote  # the tuple itself (see _sendto)
        if remote is None:
            return
        try:
            self._sendto(data, remote)
        except OSError as err:
            self.stats.tx_errors += 1
            log.debug("%s: sendto %s failed: %s", self.name, self.remote, err)
            return
        self.stats.tx_datagrams += 1
        self.stats.tx_bytes += len(data)

    def close(self) -> None:
        self._sock.close()

    def _note_sender(self, addr: Address) -> None:
        if not self.peer_latched:
            self.peer_latched = True
            if addr != self.remote:
                log.info("%s link: partner is now %s:%d", self.name, addr[0], addr[1])
            self.remote = addr
        elif addr != self.remote:
            self.stats.rx_ignored_foreign += 1


def _open_socket(bind_host: str, port: int, name: str) -> socket.socket:
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, _RCVBUF_BYTES)
        sock.bind((bind_host, port))
    except OSError as err:
        sock.close()
        if err.errno == errno.EADDRINUSE:
            raise PortInUseError(
                f"UDP port {port} ({name} link) is already in use on {bind_host}; stop the program using it "
                f"(another PX4 or sitl-emu?) or pick another port or --instance."
            ) from None
        if err.errno in (errno.EADDRNOTAVAIL, errno.EACCES):
            raise PortInUseError(f"Cannot bind UDP {bind_host}:{port} ({name} link): {err.strerror}.") from None
        raise
    sock.setblocking(False)
    return sock
