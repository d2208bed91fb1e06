"""In-memory LinkContext and a small stand-in Vehicle for unit tests of the protocol handlers and shells.

What a handler sends is framed by the endpoint's encoder (fastpack) and parsed back by pymavlink's parser, so tests
see exactly what a client would receive.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from pymavlink.dialects.v20 import development as dialect

from sitl_emu.events.catalogue import Px4Event, to_px4_event
from sitl_emu.mavlink.wire.fastpack import ENCODER, Packed, frame_message
from sitl_emu.navigator.mission_store import MissionStore
from sitl_emu.params import ParamRegistry, default_registry
from sitl_emu.px4 import LandedState, MavResult, NavState, Severity
from sitl_emu.types import CommandAck, VehicleCommand, VehicleEvent, VehicleSnapshot

CLIENT_SYSID = 255
CLIENT_COMPID = 190


class _Sink:
    def __init__(self) -> None:
        self.chunks: list[bytes] = []

    def write(self, buf: bytes | bytearray) -> None:
        self.chunks.append(bytes(buf))


def _parse(data: bytes) -> list[Any]:
    parser = dialect.MAVLink(None, srcSystem=0, srcComponent=0)
    return parser.parse_buffer(data) or []


class Client:
    """Encodes messages as a ground station (sysid 255, compid 190) would send them, through real bytes."""

    def __init__(self, sysid: int = CLIENT_SYSID, compid: int = CLIENT_COMPID) -> None:
        self._sink = _Sink()
        self.mav = dialect.MAVLink(self._sink, srcSystem=sysid, srcComponent=compid)

    def msg(self, name: str, *args: Any) -> Any:
        encode = getattr(self.mav, f"{name.lower()}_encode")
        self.mav.send(encode(*args))
        (parsed,) = _parse(self._sink.chunks.pop())
        return parsed


class MemoryContext:
    """A LinkContext that records what handlers send (decoded from the real wire bytes)."""

    def __init__(self, vehicle: Any, link_name: str = "api", sysid: int = 1, compid: int = 1) -> None:
        self.vehicle = vehicle
        self.link_name = link_name
        self.sysid = sysid
        self.compid = compid
        self.encoder = ENCODER
        self.seq = 0
        self._now_us = 0
        self.sent: list[Any] = []
        self.broadcasts: list[Any] = []

    @property
    def now_us(self) -> int:
        return self._now_us

    def advance(self, dt_us: int) -> None:
        self._now_us += dt_us

    def _frame(self, msg: Packed) -> bytes:
        frame = frame_message(msg, self.seq, self.sysid, self.compid)
        self.seq = (self.seq + 1) % 256
        return frame

    def send(self, msg: Packed) -> None:
        self.sent.extend(_parse(self._frame(msg)))

    def broadcast(self, msg: Packed) -> None:
        self.broadcasts.extend(_parse(self._frame(msg)))

    def take(self, msg_type: str | None = None) -> list[Any]:
        """Sent messages (of one type, if given) since the last take; clears the record."""
        taken = [m for m in self.sent if msg_type is None or m.get_type() == msg_type]
        self.sent.clear()
        return taken


def make_snapshot(**overrides: Any) -> VehicleSnapshot:
    nan3 = (math.nan, math.nan, math.nan)
    fields: dict[str, Any] = dict(
        time_us=0, armed=False, nav_state=NavState.AUTO_LOITER, user_intended_nav_state=NavState.AUTO_LOITER,
        failsafe=False, landed_state=LandedState.ON_GROUND, pre_flight_checks_pass=True, position_valid=True,
        takeoff_detected=False, offboard_control=None, pos_ned_m=(0.0, 0.0, 0.0), vel_ned_m_s=(0.0, 0.0, 0.0),
        acc_ned_m_s2=(0.0, 0.0, 0.0), q_wxyz=(1.0, 0.0, 0.0, 0.0), rates_frd_rad_s=(0.0, 0.0, 0.0),
        euler_rad=(0.0, 0.0, 0.0), lat_deg=47.397742, lon_deg=8.545594, alt_amsl_m=488.0, ref_lat_deg=47.397742,
        ref_lon_deg=8.545594, ref_alt_amsl_m=488.0, home=None, local_setpoint=None, attitude_setpoint_q_wxyz=None,
        rates_setpoint_rad_s=nan3, thrust_setpoint=0.0, motors=(0.0, 0.0, 0.0, 0.0),
    )
    fields.update(overrides)
    return VehicleSnapshot(**fields)


class FakeVehicle:
    """The attributes of sitl_emu.vehicle.vehicle.Vehicle the handlers and shells use, with scripted command results.

    `results` maps a MAV_CMD number to the MavResult to answer (default ACCEPTED); `on_command` lets a test react
    (e.g. report an event) when a command arrives.
    """

    def __init__(self, params: ParamRegistry | None = None, sysid: int = 1) -> None:
        self.params = params if params is not None else default_registry()
        self.sysid = sysid
        self.time_us = 0
        self.commands: list[VehicleCommand] = []
        self.results: dict[int, int | None] = {}
        self.on_command: Callable[[VehicleCommand], None] | None = None
        self.snap = make_snapshot()
        self._events: list[VehicleEvent] = []
        self._missions = MissionStore()

    def mission_store(self) -> MissionStore:
        return self._missions

    def handle_command(self, cmd: VehicleCommand) -> CommandAck | None:
        self.commands.append(cmd)
        if self.on_command is not None:
            self.on_command(cmd)
        result = self.results.get(cmd.command, MavResult.ACCEPTED)
        return None if result is None else CommandAck(cmd.command, result)

    def snapshot(self) -> VehicleSnapshot:
        return self.snap

    def report(self, severity: Severity, module: str, text: str, is_event: bool = True) -> None:
        seq = self._events[-1].seq + 1 if self._events else 0
        self._events.append(VehicleEvent(seq, self.time_us, severity, module, text, is_event))

    def events_after(self, seq: int) -> list[VehicleEvent]:
        return [e for e in self._events if e.seq > seq]

    def px4_events_after(self, seq: int) -> list[tuple[int, Px4Event]]:
        """The PX4 event each text goes with (as the Vehicle's stream has them), numbered by the text's seq."""
        return [(e.seq, px4) for e in self._events if e.seq > seq and (px4 := to_px4_event(e)) is not None]

    @property
    def events(self) -> list[VehicleEvent]:
        return list(self._events)
