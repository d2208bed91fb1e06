"""Test doubles for the MAVLink side: a scripted Vehicle with the real interface, and a loopback UDP MAVLink client.

`FakeVehicle` records every input and answers commands from a table, so receiver tests see exactly what the wire
produced. `Client` is a pymavlink peer on 127.0.0.1 with a free port; `Harness` wires a VehicleNode to it and steps
both in lockstep (simulated time, no sleeps): loopback UDP delivers before sendto() returns.
"""

from __future__ import annotations

import math
import socket
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field, replace
from typing import Any

from pymavlink.dialects.v20 import development as dialect

from sitl_emu.events.catalogue import Px4Event, to_px4_event
from sitl_emu.px4 import LandedState, MavResult, NavState, Severity
from sitl_emu.runtime.node import LinkSettings, VehicleNode
from sitl_emu.types import (
    AttitudeSetpoint,
    CommandAck,
    HomePosition,
    OffboardControlMode,
    TrajectorySetpoint,
    VehicleCommand,
    VehicleEvent,
    VehicleSnapshot,
)

HOME = (47.397742, 8.545594, 488.0)


def ready_snapshot(time_us: int = 0, **changes: Any) -> VehicleSnapshot:
    """A disarmed, ready vehicle in Hold on the ground at HOME."""
    snap = VehicleSnapshot(
        time_us=time_us, armed=False, nav_state=NavState.AUTO_LOITER, user_intended_nav_state=NavState.AUTO_LOITER,
        failsafe=False, landed_state=LandedState.ON_GROUND, pre_flight_checks_pass=True, position_valid=True,
        takeoff_detected=False, offboard_control=None, pos_ned_m=(0.0, 0.0, 0.0), vel_ned_m_s=(0.0, 0.0, 0.0),
        acc_ned_m_s2=(0.0, 0.0, 0.0), q_wxyz=(1.0, 0.0, 0.0, 0.0), rates_frd_rad_s=(0.0, 0.0, 0.0),
        euler_rad=(0.0, 0.0, 0.0), lat_deg=HOME[0], lon_deg=HOME[1], alt_amsl_m=HOME[2], ref_lat_deg=HOME[0],
        ref_lon_deg=HOME[1], ref_alt_amsl_m=HOME[2], home=HomePosition(*HOME, (0.0, 0.0, 0.0), 0.0),
        local_setpoint=None, attitude_setpoint_q_wxyz=None, rates_setpoint_rad_s=(0.0, 0.0, 0.0),
        thrust_setpoint=0.0, motors=(0.0, 0.0, 0.0, 0.0))
    return replace(snap, **changes)


@dataclass
class FakeVehicle:
    """The Vehicle interface with recorded inputs; `acks` maps a command id to the result to answer."""

    sysid: int = 1
    dt_us: int = 4000
    time_us: int = 0
    acks: dict[int, int | None] = field(default_factory=dict)
    default_result: int = MavResult.ACCEPTED
    commands: list[VehicleCommand] = field(default_factory=list)
    offboard: list[tuple[OffboardControlMode, TrajectorySetpoint | None, AttitudeSetpoint | None]] = field(
        default_factory=list)
    events: list[VehicleEvent] = field(default_factory=list)
    snap_changes: dict[str, Any] = field(default_factory=dict)
    params: Any = None
    gcs_heartbeats: int = 0  # ground-station heartbeats the receiver passed on (the data-link watchdog)

    def step(self) -> None:
        self.time_us += self.dt_us

    def run_until(self, time_us: int) -> None:
        while self.time_us < time_us:
            self.step()

    def handle_command(self, cmd: VehicleCommand) -> CommandAck | None:
        self.commands.append(cmd)
        result = self.acks.get(cmd.command, self.default_result)
        return None if result is None else CommandAck(cmd.command, result)

    def offboard_input(self, mode: OffboardControlMode, trajectory: TrajectorySetpoint | None = None,
                       attitude: AttitudeSetpoint | None = None) -> None:
        self.offboard.append((mode, trajectory, attitude))

    def snapshot(self) -> VehicleSnapshot:
        return ready_snapshot(self.time_us, **self.snap_changes)

    def events_after(self, seq: int) -> list[VehicleEvent]:
        return [e for e in self.events if e.seq > seq]

    def px4_events_after(self, seq: int) -> list[tuple[int, Px4Event]]:
        """The PX4 event each text goes with (as the Vehicle's stream has them), numbered by the text's seq."""
        return [(e.seq, px4) for e in self.events if e.seq > seq and (px4 := to_px4_event(e)) is not None]

    def report(self, severity: Severity, module: str, text: str, is_event: bool = True) -> None:
        self.events.append(VehicleEvent(len(self.events) + 1, self.time_us, severity, module, text, is_event))

    def reboot(self) -> None:
        self.time_us = 0

    def gcs_heartbeat(self) -> None:
        self.gcs_heartbeats += 1


class Client:
    """A MAVLink peer on a free loopback port (default identity: a GCS, sysid 255 compid 190)."""

    def __init__(self, sysid: int = 255, compid: int = 190, mavlink1: bool = False) -> None:
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 22)
        self.sock.bind(("127.0.0.1", 0))
        self.sock.setblocking(False)
        self.port = self.sock.getsockname()[1]
        self.mav = dialect.MAVLink(None, srcSystem=sysid, srcComponent=compid)
        if mavlink1:
            self.mav.WIRE_PROTOCOL_VERSION = "1.0"
        self._parser = dialect.MAVLink(None)
        self._parser.robust_parsing = True
        self.received: list[Any] = []
        self.target: tuple[str, int] | None = None
        self.senders: set[tuple[str, int]] = set()

    def send(self, msg: Any, force_mavlink1: bool = False) -> None:
        assert self.target is not None
        self.sock.sendto(msg.pack(self.mav, force_mavlink1=force_mavlink1), self.target)
        self.mav.seq = (self.mav.seq + 1) % 256

    def send_raw(self, data: bytes) -> None:
        assert self.target is not None
        self.sock.sendto(data, self.target)

    def drain(self) -> list[Any]:
        new: list[Any] = []
        while True:
            try:
                data, addr = self.sock.recvfrom(65535)
            except BlockingIOError:
                break
            self.senders.add(addr)
            new.extend(m for m in self._parser.parse_buffer(data) or [] if m.get_type() != "BAD_DATA")
        self.received.extend(new)
        return new

    def of_type(self, msg_type: str, source: tuple[int, int] | None = (1, 1)) -> list[Any]:
        """Received messages of one type from `source` (the vehicle by default; None: from anyone, e.g. forwarded)."""
        return [m for m in self.received if m.get_type() == msg_type
                and (source is None or (m.get_srcSystem(), m.get_srcComponent()) == source)]

    def heartbeat(self, mav_type: int = 6) -> None:
        self.send(self.mav.heartbeat_encode(mav_type, 8, 0, 0, 0, 3))

    def command_long(self, command: int, *params: float, target: tuple[int, int] = (1, 1)) -> None:
        p = [*params, *([math.nan] * (7 - len(params)))]
        self.send(self.mav.command_long_encode(target[0], target[1], command, 0, *p))

    def close(self) -> None:
        self.sock.close()


class Harness:
    """A node whose API link sends to `api` and GCS link to `gcs`, stepped in lockstep with both clients."""

    def __init__(self, vehicle: Any, handler_classes: Iterable[type] | None = (), epoch_unix_us: int = 0) -> None:
        self.api = Client()
        self.gcs = Client()
        settings = LinkSettings("127.0.0.1", 0, ("127.0.0.1", self.api.port), 0, ("127.0.0.1", self.gcs.port))
        classes = None if handler_classes is None else list(handler_classes)
        self.node = VehicleNode(vehicle, settings, epoch_unix_us=epoch_unix_us, handler_classes=classes)
        self.vehicle = vehicle
        self.api.target = ("127.0.0.1", self.node.api.link.port)
        self.gcs.target = ("127.0.0.1", self.node.gcs.link.port)
        self.most_read = 0  # the most datagrams one I/O pass read

    def io(self) -> None:
        """One I/O pass at the current simulated time, then collect what the clients got."""
        self.most_read = max(self.most_read, self.node.step_io(self.vehicle.time_us))
        self.api.drain()
        self.gcs.drain()

    def run(self, seconds: float, every_step: Callable[[], None] | None = None) -> None:
        """Step for `seconds` of simulated time (counted in steps, so a reboot's time reset cannot stretch it)."""
        for _ in range(round(seconds * 1e6 / self.vehicle.dt_us)):
            self.vehicle.step()
            if every_step is not None:
                every_step()
            self.io()

    def run_until(self, predicate: Callable[[], bool], timeout_s: float,
                  every_step: Callable[[], None] | None = None) -> bool:
        for _ in range(round(timeout_s * 1e6 / self.vehicle.dt_us)):
            self.vehicle.step()
            if every_step is not None:
                every_step()
            self.io()
            if predicate():
                return True
        return False

    def close(self) -> None:
        self.node.close()
        self.api.close()
        self.gcs.close()
