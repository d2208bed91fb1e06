"""Micro-benchmark: N datagrams to one loopback UDP peer, N sendto calls vs one sendmmsg(2) through ctypes.

`python -m bench.sendmmsg [--rounds R] [--batches B]` prints the CPU time (user + sys, time.process_time) per
datagram of each method for N = 1, 2, 4, 8, 16, and the saving. The messages are a realistic mix of 20-80 byte
MAVLink frames; the sendmmsg side includes its Python cost: copying each message into a preallocated buffer and
writing its iovec (no allocation per message). A third column is the system call alone on arrays filled before: the
floor that no batching code, compiled or not, could go below. The methods take turns in short rounds so a loaded
machine's drift falls on all alike. Linux only.

Why it is kept (issue 28): it decided that the links send one sendto per datagram, as PX4's send_finish() does. In
`serve` a link sends 1-33 datagrams in a tick (API link: 4 or 15-17 in most ticks that send; GCS link: 7), and on this
kernel the ~2.9 µs of a loopback datagram is the UDP stack's work per datagram, not the system call's entry (~0.13 µs):
sendmmsg saved -7 % at N=4, -1 % at N=8, +2 % at N=16, its system call alone at most 11 % at N=16. Far below the 25 %
that would pay for a batching seam.
"""

from __future__ import annotations

import argparse
import ctypes
import ctypes.util
import socket
import struct
import sys
import time
from collections.abc import Callable

SIZES_BYTES = (20, 80, 36, 52, 41, 28, 60, 33, 45, 71, 24, 39, 57, 30, 48, 66)  # frame lengths of a tick's mix


class IoVec(ctypes.Structure):
    _fields_ = [("iov_base", ctypes.c_void_p), ("iov_len", ctypes.c_size_t)]


class MsgHdr(ctypes.Structure):
    _fields_ = [("msg_name", ctypes.c_void_p), ("msg_namelen", ctypes.c_uint32),
                ("msg_iov", ctypes.c_void_p), ("msg_iovlen", ctypes.c_size_t),
                ("msg_control", ctypes.c_void_p), ("msg_controllen", ctypes.c_size_t), ("msg_flags", ctypes.c_int)]


class MMsgHdr(ctypes.Structure):
    _fields_ = [("msg_hdr", MsgHdr), ("msg_len", ctypes.c_uint)]


class BatchSender:
    """One sendmmsg per batch: messages copied into one buffer, one iovec and one mmsghdr each, all preallocated."""

    def __init__(self, sock: socket.socket, dest: tuple[str, int], capacity: int = 64) -> None:
        libc = ctypes.CDLL(ctypes.util.find_library("c"), use_errno=True)
        self._sendmmsg = libc.sendmmsg
        self._sendmmsg.argtypes = [ctypes.c_int, ctypes.c_void_p, ctypes.c_uint, ctypes.c_int]
        self._sendmmsg.restype = ctypes.c_int
        self._fd = sock.fileno()
        self._addr = ctypes.create_string_buffer(
            struct.pack("=H2s4s8x", socket.AF_INET, struct.pack("!H", dest[1]), socket.inet_aton(dest[0])))
        self._buffer = bytearray(capacity * 280)
        self._buffer_c = (ctypes.c_char * len(self._buffer)).from_buffer(self._buffer)
        base = ctypes.addressof(self._buffer_c)
        self._iov_raw = bytearray(ctypes.sizeof(IoVec) * capacity)
        iovs = (IoVec * capacity).from_buffer(self._iov_raw)
        self._iovs = iovs
        self._headers = (MMsgHdr * capacity)()
        for i in range(capacity):
            hdr = self._headers[i].msg_hdr
            hdr.msg_name = ctypes.addressof(self._addr)
            hdr.msg_namelen = 16
            hdr.msg_iov = ctypes.addressof(iovs[i])
            hdr.msg_iovlen = 1
        self._base = base
        self._headers_addr = ctypes.addressof(self._headers)

    def send(self, messages: list[bytes]) -> int:
        buffer, iov_raw, base = self._buffer, self._iov_raw, self._base
        offset = 0
        for i, data in enumerate(messages):
            end = offset + len(data)
            buffer[offset:end] = data
            struct.pack_into("PN", iov_raw, i * 16, base + offset, len(data))
            offset = end
        return int(self._sendmmsg(self._fd, self._headers_addr, len(messages), 0))

    def send_prebuilt(self, messages: list[bytes]) -> int:
        """The system call alone, on arrays `send` filled before: the floor no batching code could go below."""
        return int(self._sendmmsg(self._fd, self._headers_addr, len(messages), 0))


def _loop_sendto(sock: socket.socket, dest: tuple[str, int]) -> Callable[[list[bytes]], None]:
    def send(messages: list[bytes]) -> None:
        for data in messages:
            sock.sendto(data, dest)
    return send


def _cpu_s(send: Callable[[list[bytes]], object], messages: list[bytes], batches: int) -> float:
    start = time.process_time()
    for _ in range(batches):
        send(messages)
    return time.process_time() - start


def _drain(sink: socket.socket) -> None:
    try:
        while True:
            sink.recv(4096)
    except BlockingIOError:
        pass


def measure(n: int, rounds: int, batches: int) -> tuple[float, float, float]:
    """CPU µs per datagram of (sendto loop, sendmmsg, sendmmsg on prebuilt arrays), the methods taking turns
    `rounds` times, each round in a rotated order."""
    sink = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sink.bind(("127.0.0.1", 0))
    sink.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 22)
    sink.setblocking(False)
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.setblocking(False)
    dest = sink.getsockname()
    messages = [bytes(range(size)) for size in (SIZES_BYTES * 2)[:n]]
    loop, batch = _loop_sendto(sock, dest), BatchSender(sock, dest)
    batch.send(messages)
    _drain(sink)
    methods: list[Callable[[list[bytes]], object]] = [loop, batch.send, batch.send_prebuilt]
    totals = [0.0, 0.0, 0.0]
    for r in range(rounds):
        for k in range(3):
            index = (r + k) % 3
            totals[index] += _cpu_s(methods[index], messages, batches)
            _drain(sink)
    sock.close()
    sink.close()
    per = 1e6 / (rounds * batches * n)
    return totals[0] * per, totals[1] * per, totals[2] * per


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=40)
    parser.add_argument("--batches", type=int, default=200, help="batches per round and method")
    args = parser.parse_args()
    if not sys.platform.startswith("linux"):
        raise SystemExit("bench.sendmmsg: sendmmsg(2) is a Linux system call; run this on Linux.")
    print("CPU time per datagram (user + sys) on loopback UDP; saving = 1 - sendmmsg / sendto loop")
    print("N    sendto loop     sendmmsg  (saving)   syscall alone  (saving)")
    for n in (1, 2, 4, 8, 16):
        loop_us, batch_us, floor_us = measure(n, args.rounds, args.batches)
        print(f"{n:<3} {loop_us:8.2f} µs  {batch_us:8.2f} µs  ({_saving(loop_us, batch_us)})  "
              f"{floor_us:8.2f} µs  ({_saving(loop_us, floor_us)})", flush=True)


def _saving(before: float, after: float) -> str:
    return f"{100 * (1 - after / before):+5.1f} %"


if __name__ == "__main__":
    main()
