"""Latency from a joystick event to the setpoint datagram leaving joyfly, for the two ways joyfly reads joysticks.

Flies the built-in emulator (sitl_emu in-process, accelerated only for the take-off) with joyfly's flight session
reading the joystick in its own thread, then flips the forward stick between +0.5 and -0.5 at irregular intervals.
For each flip it takes the wall time just before the event and the wall time just after joyfly's sendto() of the
first SET_POSITION_TARGET_LOCAL_NED whose velocity feed-forward shows the new stick.
  js:  a FIFO joystick (the js API's records); the event is the write of the js_event to the FIFO.
  sdl: an SDL virtual game controller (read by SDL exactly like hardware); the event is SDL_JoystickSetVirtualAxis,
       and joyfly's thread pumps SDL's events (joyfly/sticks/sdl/source.py).

    .venv/bin/python bench/joyfly_latency.py [--events 300] [--only js|sdl]
"""

from __future__ import annotations

import argparse
import ctypes
import os
import random
import statistics
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from joyfly.demo import EmbeddedVehicle
from joyfly.link.transport import UdpTransport
from joyfly.link.vehicle_link import VehicleLink
from joyfly.session.flight_session import FlightSession, Phase, SessionSettings
from joyfly.sticks.js.reader import JS_EVENT_AXIS, JS_EVENT_BUTTON, JS_EVENT_INIT, pack_event
from joyfly.sticks.mapping import MappedSource, open_sticks
from joyfly.sticks.sdl.api import sdl_api
from joyfly.sticks.setpoints import Setpoint
from px4common.clock import WallClock


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--events", type=int, default=300)
    parser.add_argument("--only", choices=("js", "sdl"), default=None)
    args = parser.parse_args()
    if args.only in (None, "js"):
        with tempfile.TemporaryDirectory() as tmp:
            report("js ", measure_js(Path(tmp) / "js0", args.events))
    if args.only in (None, "sdl"):
        report("sdl", measure_sdl(args.events))


def report(path: str, latencies: list[float]) -> None:
    ms = sorted(x * 1e3 for x in latencies)
    if not ms:
        print(f"{path} joystick event -> setpoint datagram: nothing measured")
        return
    p99 = ms[min(len(ms) - 1, round(0.99 * (len(ms) - 1)))]
    print(f"{path} joystick event -> setpoint datagram: n={len(ms)} median {statistics.median(ms):.2f} ms, "
          f"p99 {p99:.2f} ms, max {ms[-1]:.2f} ms (stream at 20 Hz = 50 ms period)")


def measure_js(fifo: Path, events: int) -> list[float]:
    os.mkfifo(fifo)
    clock = WallClock()
    sticks = open_sticks(str(fifo), clock, profile="script")
    fd = os.open(fifo, os.O_WRONLY | os.O_NONBLOCK)
    for index in range(7):
        os.write(fd, pack_event(JS_EVENT_BUTTON | JS_EVENT_INIT, index, 0))
    for index in range(4):
        os.write(fd, pack_event(JS_EVENT_AXIS | JS_EVENT_INIT, index, 0))
    try:
        return fly(sticks, lambda value: os.write(fd, pack_event(JS_EVENT_AXIS, 0, round(value * 32767))), events)
    finally:
        os.close(fd)


def measure_sdl(events: int) -> list[float]:
    sdl = sdl_api().sdl
    desc = sdl.SDL_VirtualJoystickDesc()
    desc.version = sdl.SDL_VIRTUAL_JOYSTICK_DESC_VERSION
    desc.type, desc.naxes, desc.nbuttons = sdl.SDL_JOYSTICK_TYPE_GAMECONTROLLER, 6, 15
    desc.name = b"Bench Pad"
    index = sdl.SDL_JoystickAttachVirtualEx(ctypes.byref(desc))
    pad = sdl.SDL_JoystickOpen(index)
    try:
        sticks = open_sticks(f"sdl:{index}", WallClock())
        # the right stick's Y axis (3): pushed forward is negative
        return fly(sticks, lambda value: sdl.SDL_JoystickSetVirtualAxis(pad, 3, round(-value * 32767)), events)
    finally:
        sdl.SDL_JoystickClose(pad)
        sdl.SDL_JoystickDetachVirtual(index)


def fly(sticks: MappedSource, move: Callable[[float], object], events: int) -> list[float]:
    """Take off with the sticks centred, then flip the forward stick `events` times; the latencies in seconds."""
    clock = WallClock()
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
        return _flip(move, sent, events)
    finally:
        session.request_exit()
        thread.join(30.0)
        emulator.stop()
        sticks.close()


def _flip(move: Callable[[float], object], sent: list[tuple[float, Setpoint]], events: int) -> list[float]:
    rng = random.Random(1)
    out: list[float] = []
    sign = 1.0
    for _ in range(events):
        time.sleep(rng.uniform(0.06, 0.14))
        start_index = len(sent)
        t_event = time.perf_counter()
        move(0.5 * sign)
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
