"""A small scripted MAVLink client (pymavlink messages over a UDP socket) on an injected clock, and a reference flight.

`FlightClient` behaves like an offboard companion: it talks first (so the vehicle's API link latches it), sends a
HEARTBEAT every second, streams the current position setpoint at 20 Hz while one is set, and waits only through
its clock. With `Sim.clock` (lockstep) a whole flight runs as fast as the CPU allows and is reproducible; with a
`px4common.clock.ScaledClock(speed)` the same script flies `sitl-emu serve --speed speed` in another process.

It decodes only the messages it reads (OBSERVED, and what `watch()` adds; testing/frames.py): the other ~80 % of
an API link's streams are skipped by their header's message id, on Linux already in the kernel
(testing/kernel_filter.py: they never reach Python; `kernel_filter=False` turns that off, with the same results).

`fly_square()` is the reference flight of the tests and the benchmark: wait until healthy, arm, take off, OFFBOARD
square (PX4's rule: setpoints stream before the switch, reference 4.2), land, wait for the auto-disarm.
"""

from __future__ import annotations

import math
import socket
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import partial
from typing import Any, Protocol

from pymavlink.dialects.v20 import development as dialect

from sitl_emu.px4 import MODE_FLAG_SAFETY_ARMED, MavCmd, MavResult, NavState, custom_mode, decode_custom_mode, main_sub
from sitl_emu.testing import kernel_filter
from sitl_emu.testing.frames import MessageFilter

NAN = math.nan
SETPOINT_PERIOD_S = 0.05  # 20 Hz, as MAVSDK's offboard plugin streams
POLL_S = 0.01
POSITION_ONLY = 0b0000_1111_1111_1000  # SET_POSITION_TARGET_LOCAL_NED type_mask: use x, y, z only
MAV_FRAME_LOCAL_NED = 1
MAV_STATE_STANDBY = 3
# the messages _observe reads: only these are decoded
OBSERVED = ("HEARTBEAT", "LOCAL_POSITION_NED", "SYS_STATUS", "HOME_POSITION", "COMMAND_ACK", "STATUSTEXT",
            "MISSION_REQUEST_INT", "MISSION_REQUEST", "MISSION_ACK", "MISSION_COUNT", "MISSION_ITEM_INT",
            "MISSION_ITEM_REACHED", "MISSION_CURRENT")
# streamed often, read now and then: the newest frame is kept and decoded when read (Observed.lat_lon_deg)
KEPT_LAST = ("GLOBAL_POSITION_INT",)


def _none(name: str) -> Any:
    return None


class Clock(Protocol):
    def now(self) -> float: ...

    def sleep(self, seconds: float) -> None: ...


class FlightError(Exception):
    """A step of a scripted flight did not happen in time; the message says which."""


@dataclass(slots=True)
class Observed:
    """What the client has heard from the vehicle."""

    heartbeat: Any = None
    first_heartbeat_s: float | None = None
    sys_status: Any = None
    home_seen: bool = False
    pos_ned_m: tuple[float, float, float] | None = None
    vehicle_time_s: float = 0.0  # the vehicle's time since boot, from LOCAL_POSITION_NED.time_boot_ms
    acks: list[tuple[int, int]] = field(default_factory=list)
    modes: list[str] = field(default_factory=list)  # distinct consecutive HEARTBEAT modes, e.g. "AUTO.LOITER"
    texts: list[str] = field(default_factory=list)
    mission: list[Any] = field(default_factory=list)  # mission protocol answers (testing/mission_client.py)
    reached: list[int] = field(default_factory=list)  # MISSION_ITEM_REACHED seqs as they change
    mission_current: Any = None  # the last MISSION_CURRENT
    last: Callable[[str], Any] = _none  # the newest message of a KEPT_LAST kind, decoded when asked

    @property
    def lat_lon_deg(self) -> tuple[float, float] | None:
        """From the newest GLOBAL_POSITION_INT (50 Hz on the API link), decoded only when this is read."""
        msg = self.last("GLOBAL_POSITION_INT")
        return None if msg is None else (msg.lat * 1e-7, msg.lon * 1e-7)


class FlightClient:
    """A MAVLink peer of one vehicle's link at `address`, identifying as sysid/compid (default: onboard 255/190)."""

    def __init__(self, address: tuple[str, int], clock: Clock, target_sysid: int = 1,
                 sysid: int = 255, compid: int = 190, kernel_filter: bool = True) -> None:
        self.clock = clock
        self.address = address
        self.target = (target_sysid, 1)
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 21)
        self.sock.bind(("127.0.0.1", 0))
        self.sock.setblocking(False)
        self.mav = dialect.MAVLink(None, srcSystem=sysid, srcComponent=compid)
        self._parser = MessageFilter(OBSERVED)
        self._parser.keep_last(*KEPT_LAST)
        self._kernel_filter = kernel_filter
        self._prefilter()
        self.seen = Observed(last=self._parser.last)
        self.setpoint_ned_m: tuple[float, float, float] | None = None
        self._next_heartbeat_s = -math.inf
        self._next_setpoint_s = -math.inf
        self.start_s = clock.now()

    # --- I/O -----------------------------------------------------------------------------------------------------
    def watch(self, *names: str) -> None:
        """Decode these messages too (e.g. "ORBIT_EXECUTION_STATUS"), for a subclass's `_observe` to read; those that
        arrive from now on (best called before the first pump())."""
        self._parser.add(*names)
        self._prefilter()

    def watch_all(self) -> None:
        """Decode every message (a client that records everything it hears)."""
        self._parser.add_all()
        self._prefilter()

    def _prefilter(self) -> None:
        """The kernel drops the single-frame datagrams of messages the parser skips (nothing off Linux)."""
        if self._kernel_filter:
            kernel_filter.attach(self.sock, self._parser.ids_read())

    def send(self, msg: Any) -> None:
        self.sock.sendto(msg.pack(self.mav), self.address)
        self.mav.seq = (self.mav.seq + 1) % 256

    def pump(self) -> None:
        """Read what arrived, then send the heartbeat and setpoint that are due."""
        while True:
            try:
                data = self.sock.recv(65535)
            except (BlockingIOError, InterruptedError, ConnectionRefusedError):
                break
            for msg in self._parser.parse(data):
                self._observe(msg)
        now = self.clock.now()
        if now >= self._next_heartbeat_s:
            self.send(self.mav.heartbeat_encode(18, 8, 0, 0, 4))  # MAV_TYPE_ONBOARD_CONTROLLER, AUTOPILOT_INVALID
            self._next_heartbeat_s = now + 1.0
        if self.setpoint_ned_m is not None and now >= self._next_setpoint_s:
            self._send_setpoint(self.setpoint_ned_m)
            self._next_setpoint_s = now + SETPOINT_PERIOD_S

    def _send_setpoint(self, ned: tuple[float, float, float]) -> None:
        boot_ms = int((self.clock.now() - self.start_s) * 1000) & 0xFFFFFFFF
        self.send(self.mav.set_position_target_local_ned_encode(
            boot_ms, *self.target, MAV_FRAME_LOCAL_NED, POSITION_ONLY, *ned, 0, 0, 0, 0, 0, 0, NAN, NAN))

    def _observe(self, msg: Any) -> None:
        kind = msg.get_type()
        if kind == "HEARTBEAT" and msg.get_srcSystem() == self.target[0]:
            self._on_heartbeat(msg)
        elif kind == "LOCAL_POSITION_NED":
            self.seen.pos_ned_m = (msg.x, msg.y, msg.z)
            self.seen.vehicle_time_s = msg.time_boot_ms / 1000.0
        elif kind == "SYS_STATUS":
            self.seen.sys_status = msg
        elif kind == "HOME_POSITION":
            self.seen.home_seen = True
        elif kind == "COMMAND_ACK":
            self.seen.acks.append((msg.command, msg.result))
        elif kind == "STATUSTEXT":
            self.seen.texts.append(msg.text)
        elif kind in ("MISSION_REQUEST_INT", "MISSION_REQUEST", "MISSION_ACK", "MISSION_COUNT", "MISSION_ITEM_INT"):
            self.seen.mission.append(msg)
        elif kind == "MISSION_ITEM_REACHED" and (not self.seen.reached or self.seen.reached[-1] != msg.seq):
            self.seen.reached.append(msg.seq)  # PX4 repeats the last one (1 Hz, 10 times): kept once
        elif kind == "MISSION_CURRENT":
            self.seen.mission_current = msg

    def _on_heartbeat(self, msg: Any) -> None:
        if self.seen.first_heartbeat_s is None:
            self.seen.first_heartbeat_s = self.clock.now()
        self.seen.heartbeat = msg
        name = _mode_name(msg.custom_mode)
        if not self.seen.modes or self.seen.modes[-1] != name:
            self.seen.modes.append(name)

    # --- waiting and commanding ---------------------------------------------------------------------------------
    def wait(self, predicate: Callable[[], bool], timeout_s: float, what: str) -> float:
        """Pump until `predicate()`; returns the time waited (clock seconds). FlightError after `timeout_s`."""
        start = self.clock.now()
        while True:
            self.pump()
            if predicate():
                return self.clock.now() - start
            if self.clock.now() - start > timeout_s:
                raise FlightError(f"Timed out after {timeout_s:g} s waiting for {what}.")
            self.clock.sleep(POLL_S)

    def spin(self, seconds: float) -> None:
        end = self.clock.now() + seconds
        while self.clock.now() < end:
            self.pump()
            self.clock.sleep(min(POLL_S, end - self.clock.now()))

    def _acked(self, command: int, since: int) -> bool:
        return any(c == command for c, _ in self.seen.acks[since:])

    def command(self, command: int, *params: float, timeout_s: float = 1.0, tries: int = 3) -> int:
        """COMMAND_LONG, resent up to `tries` times (confirmation counts up, as MAVSDK does); the ACK result."""
        p = [*params, *([NAN] * (7 - len(params)))]
        for confirmation in range(tries):
            n = len(self.seen.acks)
            self.send(self.mav.command_long_encode(*self.target, command, confirmation, *p))
            try:
                self.wait(partial(self._acked, command, n), timeout_s, f"ACK {command}")
            except FlightError:
                continue
            return next(r for c, r in self.seen.acks[n:] if c == command)
        raise FlightError(f"No COMMAND_ACK for command {command} after {tries} tries.")

    def set_mode(self, nav_state: NavState) -> int:
        main, sub = main_sub(nav_state)
        return self.command(MavCmd.DO_SET_MODE, 1, main, sub)  # base mode: custom

    # --- state ---------------------------------------------------------------------------------------------------
    @property
    def armed(self) -> bool:
        hb = self.seen.heartbeat
        return hb is not None and bool(hb.base_mode & MODE_FLAG_SAFETY_ARMED)

    def in_mode(self, nav_state: NavState) -> bool:
        hb = self.seen.heartbeat
        return hb is not None and hb.custom_mode == custom_mode(nav_state)

    @property
    def healthy(self) -> bool:
        """MAVSDK-style 'health all ok': every present sensor healthy (incl. pre-arm checks) and home known."""
        st, hb = self.seen.sys_status, self.seen.heartbeat
        if st is None or hb is None or not self.seen.home_seen:
            return False
        present = st.onboard_control_sensors_present
        return (st.onboard_control_sensors_health & present) == present and hb.system_status == MAV_STATE_STANDBY

    def close(self) -> None:
        self.sock.close()


def _mode_name(custom: int) -> str:
    from sitl_emu.px4 import mode_name, nav_state_from_main_sub

    nav = nav_state_from_main_sub(*decode_custom_mode(custom))
    return mode_name(nav) if nav is not None else f"custom {custom:#x}"


@dataclass(frozen=True, slots=True)
class FlightResult:
    ok: bool
    modes: tuple[str, ...]
    landing_ned_m: tuple[float, float, float] | None
    sim_duration_s: float  # on the client's clock
    error: str = ""
    vehicle_duration_s: float = 0.0  # on the vehicle's clock (LOCAL_POSITION_NED.time_boot_ms)


def fly_square(client: FlightClient, side_m: float = 5.0, altitude_m: float = 2.5) -> FlightResult:
    """Arm, take off, fly an OFFBOARD square of `side_m` at the takeoff altitude, land, wait for disarm."""
    start = client.clock.now()
    client.pump()
    vehicle_start_s = client.seen.vehicle_time_s
    try:
        _square_steps(client, side_m, altitude_m)
        ok, error = True, ""
    except FlightError as err:
        ok, error = False, str(err)
    client.setpoint_ned_m = None
    return FlightResult(ok, tuple(client.seen.modes), client.seen.pos_ned_m, client.clock.now() - start, error,
                        client.seen.vehicle_time_s - vehicle_start_s)


def _square_steps(c: FlightClient, side_m: float, altitude_m: float) -> None:
    c.wait(lambda: c.healthy, 30.0, "health all good")
    _expect(c.command(MavCmd.COMPONENT_ARM_DISARM, 1), "arm")
    _expect(c.command(MavCmd.NAV_TAKEOFF, NAN, NAN, NAN, NAN, NAN, NAN, NAN), "takeoff")
    c.wait(lambda: c.seen.pos_ned_m is not None and -c.seen.pos_ned_m[2] > altitude_m - 0.2, 30.0, "takeoff altitude")
    c.wait(lambda: c.in_mode(NavState.AUTO_LOITER), 30.0, "Hold after takeoff")
    assert c.seen.pos_ned_m is not None
    z = c.seen.pos_ned_m[2]
    c.setpoint_ned_m = c.seen.pos_ned_m
    c.spin(0.5)  # PX4 needs a fresh setpoint before it accepts OFFBOARD
    _expect(c.set_mode(NavState.OFFBOARD), "OFFBOARD")
    for north, east in ((side_m, 0.0), (side_m, side_m), (0.0, side_m), (0.0, 0.0)):
        c.setpoint_ned_m = (north, east, z)
        c.wait(partial(_near, c, north, east, 0.3), 20.0, f"corner ({north:g}, {east:g})")
    c.spin(1.0)
    _expect(c.command(MavCmd.NAV_LAND), "land")
    c.setpoint_ned_m = None
    c.wait(lambda: not c.armed, 40.0, "landing and auto-disarm")


def _near(c: FlightClient, north: float, east: float, tolerance_m: float) -> bool:
    pos = c.seen.pos_ned_m
    return pos is not None and math.hypot(pos[0] - north, pos[1] - east) < tolerance_m


def _expect(result: int, what: str) -> None:
    if result != MavResult.ACCEPTED:
        raise FlightError(f"{what} was refused: {MavResult(result).name}.")
