"""The floor under the core-with-I/O figure on this machine: what loopback UDP alone costs (issue 28).

PX4 sends every MAVLink message as a datagram of its own (mavlink_main.cpp send_finish), and its onboard stream set on
the API link is ~430 messages a simulated second, so the figure "core with I/O" pays the kernel's UDP work for each
of them, however cheaply they are built. This measures, on this machine, the CPU (user + system, process_time) per
datagram of a bare Python loop over two loopback sockets:

- sent and read: `sendto` and the receiver's `recv`;
- sent and dropped: `sendto` alone, the receiving socket's kernel buffer full, so the kernel drops it on arrival (as
  it drops what a socket filter refuses: a client that reads only some messages pays for the rest this way).

With the core's own cost (the no-I/O figure) that gives the highest figure the I/O could allow if building, framing,
filtering and parsing messages cost nothing: 1 / (1 / core + datagrams a simulated second x CPU per datagram), for
a client that reads every datagram and for one that reads none.

`python -m bench.udp_floor` prints it with the pure core figure of this process.
"""

from __future__ import annotations

import socket
import time

SIZES_BYTES = (20, 80, 36, 52, 41, 28, 60, 33, 45, 71, 24, 39, 57, 30, 48, 66)  # frame lengths of a tick's mix
BURST = 16  # datagrams sent before they are read: a tick's burst


def cpu_per_datagram_s(read: bool, count: int = 64_000) -> float:
    """CPU seconds per loopback datagram sent (and read, or dropped by the receiver's kernel when `read` is False)."""
    sender = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    receiver = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        sender.bind(("127.0.0.1", 0))
        receiver.bind(("127.0.0.1", 0))
        receiver.setblocking(False)
        if not read:
            receiver.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1)  # the kernel's minimum: full at once
        destination = receiver.getsockname()
        frames = [bytes(size) for size in SIZES_BYTES]
        if not read:
            for frame in frames * 8:  # fill the buffer before timing
                sender.sendto(frame, destination)
        cpu = time.process_time()
        for _ in range(count // BURST):
            for frame in frames:
                sender.sendto(frame, destination)
            if read:
                for _ in frames:
                    receiver.recv(2048)
        return (time.process_time() - cpu) / (count // BURST * BURST)
    finally:
        sender.close()
        receiver.close()


def api_datagrams_per_sim_s() -> float:
    """Datagrams the API link sends a simulated second in core_speed_with_io's run (its default streams)."""
    from bench.core import io_run

    sim_s, api_datagrams = io_run()[1:]
    return api_datagrams / sim_s


def ceiling(core: float, datagrams: float, cpu_per_datagram_s: float) -> float:
    """The highest simulated s per CPU s with the core at `core` and only the bare UDP cost on top."""
    return 1.0 / (1.0 / core + datagrams * cpu_per_datagram_s)


def floor_text(core: float) -> str:
    """One line: the ceilings for a client that reads every datagram and for one that reads none."""
    rate = api_datagrams_per_sim_s()
    read, dropped = cpu_per_datagram_s(read=True), cpu_per_datagram_s(read=False)
    return (f"loopback UDP floor: {read * 1e6:.2f} us CPU per datagram sent and read, {dropped * 1e6:.2f} us sent and "
            f"dropped (bare Python loop); at the API link's {rate:.0f} datagrams per simulated second and a core of "
            f"{core:.0f}, core with I/O could reach at most {ceiling(core, rate, read):.0f} (client reads every "
            f"datagram) to {ceiling(core, rate, dropped):.0f} (client reads none) simulated s per CPU s with messages "
            "that cost nothing to build and parse")


if __name__ == "__main__":
    from bench.core import core_speed

    print(floor_text(core_speed()[0]))
