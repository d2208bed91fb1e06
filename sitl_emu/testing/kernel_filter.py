"""A kernel prefilter for a scripted client's UDP socket: datagrams of messages nobody reads never reach Python.

What: a classic BPF program, attached with SO_ATTACH_FILTER, that drops a datagram only when it is exactly one
unsigned MAVLink 2 frame (magic 0xFD, incompat flag bit 0 clear, length == 10 + its len byte + 2) or exactly one
MAVLink 1 frame (magic 0xFE, length == 6 + its len byte + 2) whose message id (v2: bytes 7-9 little-endian, v1: byte
5) is not in the set given. Every other datagram passes: several frames, signed frames, frames cut short or too
long, garbage, empty datagrams.

Why: PX4's onboard stream set sends ~430 messages a simulated second to a client on the API link, one per datagram,
and a scripted client reads ~10-20 % of them. Skipping the rest by their header in Python (testing/frames.py
MessageFilter) still costs a recv() and some Python per datagram; in the kernel they cost neither.

Limits: the program only drops what MessageFilter would skip anyway, so MessageFilter stays the one place that
decides what is decoded, and what a client observes is the same with or without it, with one exception: a change of
the set (attach() again) applies to datagrams that arrive after it; those already queued were sorted by the previous
set. Linux only (on another system, or if setsockopt refuses, attach() does nothing and returns False: everything
reaches Python, as without it). A set of more than MAX_IDS ids is not filtered (one compare per id). The data of a
UDP socket filter starts at the UDP header: the MAVLink bytes begin at offset 8 (tests/sitl_emu/testing/
test_kernel_filter.py checks this on the running kernel).
"""

from __future__ import annotations

import contextlib
import ctypes
import socket
import sys
from collections.abc import Collection

__all__ = ["MAX_IDS", "attach", "attach_program", "detach", "program"]

SO_ATTACH_FILTER = 26  # <asm-generic/socket.h>
SO_DETACH_FILTER = 27
MAX_IDS = 100
UDP_HEADER = 8  # where a UDP socket filter's packet data has the datagram's first byte
PASS, DROP = 0xFFFF_FFFF, 0  # a socket filter returns how many bytes to keep

# classic BPF opcodes (<linux/filter.h>)
LD_LEN = 0x00 | 0x00 | 0x80  # BPF_LD | BPF_W | BPF_LEN: A = packet length
LDB_ABS = 0x00 | 0x10 | 0x20  # BPF_LD | BPF_B | BPF_ABS: A = byte at k (out of bounds: the program returns 0)
TAX = 0x07 | 0x00  # BPF_MISC | BPF_TAX: X = A
ADD_K, LSH_K, OR_X = 0x04 | 0x00 | 0x00, 0x04 | 0x60 | 0x00, 0x04 | 0x40 | 0x08  # BPF_ALU ops
JA, JEQ_K, JGE_K, JSET_K, JEQ_X = 0x05 | 0x00, 0x05 | 0x10, 0x05 | 0x30, 0x05 | 0x40, 0x05 | 0x10 | 0x08
RET_K = 0x06 | 0x00

MAGIC_V1, MAGIC_V2 = 0xFE, 0xFD
HEADER_V1, HEADER_V2, CHECKSUM = 6, 10, 2

Insn = tuple[int, int, int, int]  # code, jt, jf, k


class _Insn(ctypes.Structure):
    _fields_ = [("code", ctypes.c_uint16), ("jt", ctypes.c_uint8), ("jf", ctypes.c_uint8), ("k", ctypes.c_uint32)]


class _Prog(ctypes.Structure):
    _fields_ = [("len", ctypes.c_ushort), ("filter", ctypes.POINTER(_Insn))]


def attach(sock: socket.socket, passed_ids: Collection[int] | None) -> bool:
    """Let through `sock` only the single frames of `passed_ids` (and everything not a single frame); None: all.

    True if the kernel filters now; False if not (not Linux, too many ids, or setsockopt refused)."""
    if passed_ids is None or len(passed_ids) > MAX_IDS or not sys.platform.startswith("linux"):
        detach(sock)
        return False
    return attach_program(sock, program(passed_ids))


def attach_program(sock: socket.socket, insns: list[Insn]) -> bool:
    """Attach these BPF instructions to `sock` (replacing its filter); False if setsockopt refuses them."""
    array = (_Insn * len(insns))(*(_Insn(*insn) for insn in insns))
    prog = _Prog(len(insns), array)  # struct sock_fprog: the kernel copies the instructions
    try:
        sock.setsockopt(socket.SOL_SOCKET, SO_ATTACH_FILTER, ctypes.string_at(ctypes.addressof(prog),
                                                                              ctypes.sizeof(prog)))
    except OSError:
        return False
    return True


def detach(sock: socket.socket) -> None:
    """Every datagram reaches Python again (nothing happens if no filter is attached, or not on Linux)."""
    if sys.platform.startswith("linux"):
        with contextlib.suppress(OSError):  # ENOENT: no filter attached
            sock.setsockopt(socket.SOL_SOCKET, SO_DETACH_FILTER, 0)


def program(passed_ids: Collection[int]) -> list[Insn]:
    """The BPF program: (code, jt, jf, k) instructions; jumps are resolved from the labels of _assembly()."""
    lines = _assembly(sorted(set(passed_ids)))
    labels: dict[str, int] = {}
    insns: list[tuple[int, str | int, str | int, int | str]] = []
    for line in lines:
        if isinstance(line, str):
            labels[line] = len(insns)
        else:
            insns.append(line)
    out: list[Insn] = []
    for at, (code, jt, jf, k) in enumerate(insns):
        jt_n, jf_n = _offset(labels, at, jt), _offset(labels, at, jf)
        out.append((code, jt_n, jf_n, _offset(labels, at, k) if code == JA else int(k)))
    if any(not 0 <= jt <= 255 or not 0 <= jf <= 255 for _, jt, jf, _ in out):
        raise ValueError("a BPF jump is out of range: too many message ids for one program")
    return out


def _offset(labels: dict[str, int], at: int, target: str | int) -> int:
    """A jump from instruction `at` to the label `target` counts the instructions it skips; a number stays."""
    return target if isinstance(target, int) else labels[target] - at - 1


def _assembly(ids: list[int]) -> list[str | tuple[int, str | int, str | int, int | str]]:
    """The program with labels (strings) where jumps land; each jump names a label or is 0 (the next one)."""
    v2_size, v1_size = UDP_HEADER + HEADER_V2 + CHECKSUM, UDP_HEADER + HEADER_V1 + CHECKSUM
    return [
        (LD_LEN, 0, 0, 0),
        (JGE_K, 0, "pass", UDP_HEADER + HEADER_V1),  # shorter than any frame header: Python judges it
        (LDB_ABS, 0, 0, UDP_HEADER),
        (JEQ_K, "v1", 0, MAGIC_V1),
        (JEQ_K, 0, "pass", MAGIC_V2),
        (LDB_ABS, 0, 0, UDP_HEADER + 1), (ADD_K, 0, 0, v2_size), (TAX, 0, 0, 0),
        (LD_LEN, 0, 0, 0), (JEQ_X, 0, "pass", 0),  # not exactly one unsigned frame (from here the loads are in it)
        (LDB_ABS, 0, 0, UDP_HEADER + 2), (JSET_K, "pass", 0, 0x01),  # signed: Python (and pymavlink) judge it
        (LDB_ABS, 0, 0, UDP_HEADER + 9), (LSH_K, 0, 0, 16), (TAX, 0, 0, 0),
        (LDB_ABS, 0, 0, UDP_HEADER + 8), (LSH_K, 0, 0, 8), (OR_X, 0, 0, 0), (TAX, 0, 0, 0),
        (LDB_ABS, 0, 0, UDP_HEADER + 7), (OR_X, 0, 0, 0),
        (JA, 0, 0, "ids"),
        "v1",
        (LDB_ABS, 0, 0, UDP_HEADER + 1), (ADD_K, 0, 0, v1_size), (TAX, 0, 0, 0),
        (LD_LEN, 0, 0, 0), (JEQ_X, 0, "pass", 0),
        (LDB_ABS, 0, 0, UDP_HEADER + 5),
        "ids",
        *((JEQ_K, "pass", 0, msg_id) for msg_id in ids),
        (RET_K, 0, 0, DROP),
        "pass",
        (RET_K, 0, 0, PASS),
    ]
