"""Latency from a joystick event to the setpoint datagram leaving joyfly.

Flies the built-in emulator (sitl_emu in-process, accelerated only for the take-off) with joyfly's flight session
reading a FIFO joystick, then flips the forward stick between +0.5 and -0.5 at irregular intervals. For each flip it
takes the wall time just before writing the js_event to the FIFO and the wall time just after joyfly's sendto() of
the first SET_POSITION_TARGET_LOCAL_NED whose velocity feed-forward shows the new stick.

    .venv/bin/python bench/joyfly_latency.py [--events 300]
"""

from __future__ import annotations

import argparse
import os
import random
import statistics
import sys
import tempfile
import threading
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from joyfly.demo import EmbeddedVehicle
from joyfly.link.transport import UdpTransport
from joyfly.link.vehicle_link import VehicleLink
from joyfly.session.flight_session import FlightSession, Phase, SessionSettings
from joyfly.sticks.joystick import JS_EVENT_AXIS, JS_EVENT_BUTTON, JS_EVENT_INIT, pack_event
from joyfly.sticks.mapping import open_sticks
from joyfly.sticks.setpoints import Setpoint
from px4common.clock import WallClock


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--events", type=int, default=300)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        latencies = measure(Path(tmp) / "js0", args.events)
    latencies.sort()
    ms = [x * 1e3 for x in latencies]
    p99 = ms[min(len(ms) - 1, round(0.99 * (len(ms) - 1)))]
    print(f"joystick event -> setpoint datagram: n={len(ms)} median {statistics.median(ms):.2f} ms, "
          f"p99 {p99:.2f} ms, max {ms[-1]:.2f} ms (stream at 20 Hz = 50 ms period)")


def measure(fifo: Path, events: int) -> list[float]:
    os.mkfifo(fifo)
    clock = WallClock()
    sticks = open_sticks(str(fifo), clock, profile="script")
    fd = os.open(fifo, os.O_WRONLY | os.O_NONBLOCK)
    for index in range(7):
        os.write(fd, pack_event(JS_EVENT_BUTTON | JS_EVENT_INIT, index, 0))
    for index in range(4):
        os.write(fd, pack_event(JS_EVENT_AXIS | JS_EVENT_INIT, index, 0))
    transport = UdpTransport(("127.0.0.1", 0), None)
    emulator = EmbeddedVehicle(transport.local_port, 1.0)
    transport.remote = emulator.api_address
    emulator.start()
    session = FlightSession(VehicleLink(transport, clock), sticks, clock, SessionSettings(fence_m=0.0))
    sent: list[tuple[float, Setpoint]] = []
    session.on_setpoint.append(lambda sp: sent.append((time.perf_counter(), sp)))
    thread = threading.Thread(target=session.run, daemon=True)
    thread.start()
    try:
        while session.phase is not Phase.FLYING:
            if session.finished:
                raise SystemExit(f"joyfly did not reach OFFBOARD: {session.error}")
            time.sleep(0.05)
        return _flip(fd, sent, events)
    finally:
        session.request_exit()
        thread.join(30.0)
        os.close(fd)
        emulator.stop()
        sticks.close()


def _flip(fd: int, sent: list[tuple[float, Setpoint]], events: int) -> list[float]:
    rng = random.Random(1)
    out: list[float] = []
    sign = 1.0
    for _ in range(events):
        time.sleep(rng.uniform(0.06, 0.14))
        start_index = len(sent)
        t_event = time.perf_counter()
        os.write(fd, pack_event(JS_EVENT_AXIS, 0, round(0.5 * sign * 32767)))
        deadline = t_event + 0.5
        while time.perf_counter() < deadline:
            hit = next((t for t, sp in sent[start_index:] if sp.vel_ned_m_s and sp.vel_ned_m_s[0] * sign > 0), None)
            if hit is not None:
                out.append(hit - t_event)
                break
            time.sleep(0.0002)
        sign = -sign
    return out


if __name__ == "__main__":
    main()
