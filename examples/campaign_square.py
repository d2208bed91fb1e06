"""A campaign scenario: take off in OFFBOARD, hold, fly a square, hold at each corner, land; flown with pymavlink.

Run it over the cases of examples/campaign_square.toml (winds from 0 to 10 m/s, GPS dropouts at drawn times):

    sitl-emu campaign examples/campaign_square.toml --out square.csv

A scenario gets an in-process `Sim` (the vehicle, stepped in lockstep: simulated time passes only in
`sim.run_for`) and the `Case` (its seed and parameters are already in the Sim; its faults and options are for the
scenario). It returns named metrics and a verdict. Your own client goes where this pymavlink code is: anything that
speaks MAVLink over UDP to `sim.ports(0).api` and waits through `sim.run_for` or `sim.clock`.

The client sends with pymavlink over a plain UDP socket and decodes only the three messages it reads
(sitl_emu.testing.frames.MessageFilter: pymavlink's parser, given only those frames). The vehicle streams ~450
messages a simulated second to it; decoding them all (pymavlink's mavutil does) would cost more CPU than the flight.
On Linux the kernel drops the datagrams of the other messages before they reach Python
(sitl_emu.testing.kernel_filter; elsewhere MessageFilter alone skips them, with the same result).

Options (case.options): side_m (0: take off, hold and land only), alt_m, hold_s, max_error_m (the pass limit on the
largest horizontal error while holding).
"""

from __future__ import annotations

import math
import socket
from typing import Any

from pymavlink.dialects.v20 import development as MAV

from sitl_emu.campaign import Case, FaultSchedule, Outcome
from sitl_emu.testing import kernel_filter
from sitl_emu.testing.frames import MessageFilter

DEFAULTS = {"side_m": 5.0, "alt_m": 3.0, "hold_s": 3.0, "max_error_m": 1.0}
METRICS = ("max_hold_error_m", "landing_offset_m", "flight_s")
MASK_POSITION = 0b0000_1111_1111_1000  # SET_POSITION_TARGET_LOCAL_NED: use x, y, z only
OFFBOARD = 6  # PX4's main mode (px4_custom_mode.h)
STEP_S = 0.05  # 20 Hz: setpoints, and how often the script looks at what came in
READS = ("HEARTBEAT", "LOCAL_POSITION_NED", "COMMAND_ACK")  # what step() reads: the only messages decoded


class NotInTime(Exception):
    """A step of the flight did not happen within its timeout."""


class Pilot:
    """A pymavlink client of the Sim's vehicle that streams a setpoint and sends the case's faults when due."""

    def __init__(self, sim: Any, case: Case) -> None:
        self.sim = sim
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(("127.0.0.1", 0))
        self.sock.setblocking(False)
        self.sock.connect(sim.ports(0).api)  # the vehicle's API link: it answers the first peer it hears
        self.mav = MAV.MAVLink(self, srcSystem=255, srcComponent=190)  # its *_send calls write() here
        self.reader = MessageFilter(READS)
        kernel_filter.attach(self.sock, self.reader.ids_read())  # the others never reach recv()
        self.faults = FaultSchedule(case.faults)
        self.setpoint: tuple[float, float, float] | None = None
        self.heartbeat: Any = None
        self.pos: tuple[float, float, float] | None = None
        self.acks: dict[int, int] = {}
        self.next_heartbeat_s = 0.0

    def now(self) -> float:
        return float(self.sim.time_us / 1e6)

    def step(self) -> None:
        """Send what is due, let STEP_S of simulated time pass, read what came in."""
        if self.now() >= self.next_heartbeat_s:
            self.mav.heartbeat_send(MAV.MAV_TYPE_ONBOARD_CONTROLLER, MAV.MAV_AUTOPILOT_INVALID, 0, 0, 0)
            self.next_heartbeat_s = self.now() + 1.0
        if self.setpoint is not None:
            self.mav.set_position_target_local_ned_send(
                0, 1, 1, MAV.MAV_FRAME_LOCAL_NED, MASK_POSITION, *self.setpoint, 0, 0, 0, 0, 0, 0, 0, 0)
        for fault in self.faults.due(self.now()):
            self.mav.command_long_send(1, 1, MAV.MAV_CMD_INJECT_FAILURE, 0, *fault.command_params())
        self.sim.run_for(STEP_S)
        for msg in self.received():
            kind = msg.get_type()
            if kind == "HEARTBEAT" and msg.get_srcSystem() == 1 and msg.get_srcComponent() == 1:
                self.heartbeat = msg
            elif kind == "LOCAL_POSITION_NED":
                self.pos = (msg.x, msg.y, msg.z)
            elif kind == "COMMAND_ACK":
                self.acks[msg.command] = msg.result

    def write(self, frame: bytes) -> None:
        """One message, one datagram to the vehicle."""
        self.sock.send(frame)

    def received(self) -> list[Any]:
        """The messages of READS that arrived since the last look (the others are skipped undecoded)."""
        msgs: list[Any] = []
        while True:
            try:
                data = self.sock.recv(65535)
            except (BlockingIOError, ConnectionRefusedError):
                return msgs
            msgs.extend(self.reader.parse(data))

    def wait(self, condition: Any, timeout_s: float, what: str) -> None:
        end = self.now() + timeout_s
        while not condition():
            if self.now() > end:
                raise NotInTime(f"no {what} within {timeout_s:g} s")
            self.step()

    def command(self, command: int, *params: float) -> None:
        self.acks.pop(command, None)
        self.mav.command_long_send(1, 1, command, 0, *params, *[0.0] * (7 - len(params)))
        self.wait(lambda: command in self.acks, 3.0, f"COMMAND_ACK for command {command}")
        if self.acks[command] != MAV.MAV_RESULT_ACCEPTED:
            raise NotInTime(f"command {command} refused (result {self.acks[command]})")

    @property
    def armed(self) -> bool:
        return self.heartbeat is not None and bool(self.heartbeat.base_mode & MAV.MAV_MODE_FLAG_SAFETY_ARMED)

    def error_to(self, target: tuple[float, float, float]) -> float:
        return math.inf if self.pos is None else math.hypot(self.pos[0] - target[0], self.pos[1] - target[1])


def fly(sim: Any, case: Case) -> Outcome:
    """The scenario: its metrics are the largest hold error, the landing offset and the flight time."""
    options = {**DEFAULTS, **case.options}
    pilot = Pilot(sim, case)
    worst = [0.0]
    try:
        pilot.wait(lambda: pilot.heartbeat is not None and pilot.heartbeat.system_status == MAV.MAV_STATE_STANDBY
                   and pilot.pos is not None, 30.0, "vehicle ready to arm")
        start_s = pilot.now()
        _fly_pattern(pilot, options, worst)
        pilot.command(MAV.MAV_CMD_NAV_LAND)
        pilot.setpoint = None
        pilot.wait(lambda: not pilot.armed, 60.0, "landing and disarm")
    except NotInTime as err:  # a flight cut short measured nothing whole: no values (empty cells), not zeros
        return Outcome(False, dict.fromkeys(METRICS), note=str(err))
    finally:
        pilot.sock.close()
    metrics = {"max_hold_error_m": worst[0], "landing_offset_m": pilot.error_to((0.0, 0.0, 0.0)),
               "flight_s": pilot.now() - start_s}
    return Outcome(worst[0] < options["max_error_m"], metrics)


def _fly_pattern(pilot: Pilot, options: dict[str, Any], worst: list[float]) -> None:
    """Arm in OFFBOARD at alt_m, hold, then the square's corners (each held), back to the start."""
    alt, side = -float(options["alt_m"]), float(options["side_m"])
    pilot.setpoint = (0.0, 0.0, alt)
    for _ in range(int(1.0 / STEP_S)):  # PX4 refuses OFFBOARD without a recent setpoint
        pilot.step()
    pilot.command(MAV.MAV_CMD_COMPONENT_ARM_DISARM, 1)
    pilot.command(MAV.MAV_CMD_DO_SET_MODE, MAV.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, OFFBOARD)
    corners = [(0.0, 0.0)] + ([(side, 0.0), (side, side), (0.0, side), (0.0, 0.0)] if side > 0 else [])
    for north, east in corners:
        target = (north, east, alt)
        pilot.setpoint = target
        pilot.wait(lambda t=target: pilot.error_to(t) < 0.5 and pilot.pos is not None
                   and abs(pilot.pos[2] - t[2]) < 0.5, 30.0, f"arrival at ({north:g}, {east:g})")
        end = pilot.now() + float(options["hold_s"])
        while pilot.now() < end:
            pilot.step()
            worst[0] = max(worst[0], pilot.error_to(target))
