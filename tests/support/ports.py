"""Free loopback UDP ports for tests that start real servers, so parallel runs never collide."""

from __future__ import annotations

import socket


def free_udp_ports(n: int) -> list[int]:
    """n distinct ports the kernel just handed out (all held at once, then released)."""
    socks = []
    for _ in range(n):
        s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        s.bind(("127.0.0.1", 0))
        socks.append(s)
    ports = [int(s.getsockname()[1]) for s in socks]
    for s in socks:
        s.close()
    return ports


def free_udp_port() -> int:
    return free_udp_ports(1)[0]


def pending_datagrams(sock: socket.socket) -> list[bytes]:
    """Every datagram waiting on a non-blocking socket."""
    out = []
    while True:
        try:
            out.append(sock.recv(65535))
        except BlockingIOError:
            return out
