"""joyfly's MAVLink client: heartbeats as a GCS, commands with retries, setpoints out, the vehicle's state in.

It speaks plain MAVLink 2 as any PX4 client does, so the same code flies real PX4 SITL and sitl-emu. The bytes go
through a `Transport` (joyfly/link/transport.py: UDP in MAVROS fcu_url style, pymavlink connection strings, or an
in-memory pair for tests).
"""

from __future__ import annotations

import logging
import math
from collections import deque
from dataclasses import dataclass, replace
from typing import Any

from pymavlink.dialects.v20 import common as mavlink2

from joyfly.link.signing import keep_up, sign_with, wall_timestamp
from joyfly.link.transport import Transport
from joyfly.sticks.setpoints import FRAME_LOCAL_NED, Setpoint
from joyfly.types import Clock
from px4common.modes import MainMode, custom_mode_name, main_mode
from px4common.results import MavResult, result_name

log = logging.getLogger(__name__)

# Our identity: a ground station, as QGC (sysid 255, compid 190 = MAV_COMP_ID_MISSIONPLANNER). PX4 sends
# STATUSTEXT only on links that heard a MAV_TYPE_GCS heartbeat in the last 2.5 s (PX4 streams/STATUSTEXT.hpp,
# Mavlink::is_gcs_connected), and explains refused mode switches only to compid 190 (Commander.cpp).
GCS_SYSID = 255
GCS_COMPID = 190
MAV_TYPE_GCS = 6
MAV_TYPE_ONBOARD_CONTROLLER = 18
MAV_AUTOPILOT_INVALID = 8
HEARTBEAT_PERIOD_S = 1.0
LINK_TIMEOUT_S = 3.0  # as MAVSDK's DEFAULT_HEARTBEAT_TIMEOUT_S (core/mavsdk_impl.hpp)
# A vehicle's time since boot (time_boot_ms of LOCAL_POSITION_NED, ATTITUDE, SYSTEM_TIME...) that goes back by more
# than this means it restarted: UDP reorders by milliseconds, and PX4's streams stamp samples at most ~0.1 s old.
RESTART_STEP_S = 1.0

# Command retries: 0.5 s timeout, 3 transmissions, as MAVSDK (core/mavlink_command_sender.cpp DEFAULT_TIMEOUT_S,
# DEFAULT_RETRIES); PX4 ACKs commander commands within one commander cycle (~10-20 ms).
COMMAND_TIMEOUT_S = 0.5
COMMAND_TRANSMISSIONS = 3

@dataclass(frozen=True, slots=True)
class VehicleState:
    """What joyfly knows of the vehicle; `None` until the matching message arrived."""

    sysid: int | None = None
    compid: int | None = None
    last_heartbeat_s: float | None = None
    armed: bool = False
    custom_mode: int = 0
    system_status: int = 0
    pos_ned_m: tuple[float, float, float] | None = None
    vel_ned_m_s: tuple[float, float, float] = (0.0, 0.0, 0.0)
    yaw_rad: float = 0.0
    landed_state: int = 0  # MAV_LANDED_STATE: 0 unknown, 1 on ground, 2 in air, 3 takeoff, 4 landing
    home_ned_m: tuple[float, float, float] | None = None
    boot_s: float | None = None  # the vehicle's time since boot, from the latest time_boot_ms
    stamped_s: float | None = None  # our time when that message arrived
    restarts: int = 0  # times its boot time went back (it restarted) since we first heard it
    uptime_before_restart_s: float | None = None  # its time since boot just before the last restart

    @property
    def mode(self) -> str:
        return custom_mode_name(self.custom_mode) if self.last_heartbeat_s is not None else "-"

    @property
    def offboard(self) -> bool:
        return main_mode(self.custom_mode) == MainMode.OFFBOARD

    @property
    def on_ground(self) -> bool:
        return self.landed_state == 1 or (self.landed_state == 0 and not self.armed)

    def link_ok(self, now_s: float) -> bool:
        return self.last_heartbeat_s is not None and now_s - self.last_heartbeat_s < LINK_TIMEOUT_S


@dataclass(frozen=True, slots=True)
class StatusText:
    time_s: float
    severity: int
    text: str


class CommandHandle:
    """A COMMAND_LONG in flight: `result` is the MAV_RESULT once ACKed; `timed_out` after the last retry."""

    def __init__(self, command: int, params: tuple[float, ...], now_s: float) -> None:
        self.command = command
        self.params = params
        self.sent_at_s = now_s
        self.transmissions = 1
        self.result: int | None = None
        self.timed_out = False

    @property
    def done(self) -> bool:
        return self.timed_out or (self.result is not None and self.result != MavResult.IN_PROGRESS)

    @property
    def accepted(self) -> bool:
        return self.result == MavResult.ACCEPTED

    def describe(self) -> str:
        if self.timed_out:
            return "no answer from the vehicle"
        return result_name(self.result) if self.result is not None else "pending"


class _Writer:
    """File-like adapter so pymavlink's *_send() methods write into the transport."""

    def __init__(self, transport: Transport) -> None:
        self._transport = transport

    def write(self, data: bytes) -> None:
        self._transport.write(bytes(data))


class VehicleLink:
    """The MAVLink conversation with one PX4 vehicle. Call `poll()` often and `tick()` at least every 0.1 s."""

    def __init__(self, transport: Transport, clock: Clock) -> None:
        self.transport = transport
        self._clock = clock
        self._mav = mavlink2.MAVLink(_Writer(transport), srcSystem=GCS_SYSID, srcComponent=GCS_COMPID)
        self._mav.robust_parsing = True
        self.state = VehicleState()
        self.statustexts: deque[StatusText] = deque(maxlen=50)
        self._unread: list[StatusText] = []
        self._pending: list[CommandHandle] = []
        self._next_heartbeat_s = -math.inf
        self._t0_s = clock.now()
        self._chunks: dict[int, str] = {}
        self.on_message: list[Any] = []  # callables(msg) for observers (benchmarks, tests)
        self._signing = False
        self._key_to_give: bytes | None = None  # SETUP_SIGNING until the vehicle's heartbeat comes signed

    def use_signing(self, key: bytes, setup: bool = False) -> None:
        """Sign everything sent with `key` and take from the vehicle only what it signs with it, but its heartbeat
        (joyfly/link/signing.py); `setup`: give the vehicle the key with SETUP_SIGNING, once it is found."""
        sign_with(self._mav, key)
        self._signing = True
        self._key_to_give = key if setup else None

    # --- receiving -------------------------------------------------------------------------------------------
    def poll(self, timeout_s: float = 0.0) -> int:
        """Read and apply everything that has arrived (waiting at most timeout_s for the first bytes)."""
        count = 0
        data = self.transport.read(timeout_s)
        while data:
            for msg in self._mav.parse_buffer(data) or []:
                self._handle(msg)
                count += 1
            data = self.transport.read(0.0)
        return count

    def _handle(self, msg: Any) -> None:
        kind = msg.get_type()
        if kind == "HEARTBEAT":
            self._on_heartbeat(msg)
            return
        if self.state.sysid is None or msg.get_srcSystem() != self.state.sysid:
            return
        boot_ms = getattr(msg, "time_boot_ms", None)
        if boot_ms is not None and msg.get_srcComponent() == self.state.compid:
            self._on_boot_time(boot_ms / 1000)
        handler = _HANDLERS.get(kind)
        if handler is not None:
            handler(self, msg)
        for observer in self.on_message:
            observer(msg)

    def _on_heartbeat(self, msg: Any) -> None:
        if msg.autopilot == MAV_AUTOPILOT_INVALID or msg.type in (MAV_TYPE_GCS, MAV_TYPE_ONBOARD_CONTROLLER):
            return  # another ground station or companion, not the vehicle
        if self.state.sysid is None:
            self.state = replace(self.state, sysid=msg.get_srcSystem(), compid=msg.get_srcComponent())
            log.info("vehicle found: sysid %d compid %d", msg.get_srcSystem(), msg.get_srcComponent())
        if msg.get_srcSystem() != self.state.sysid or msg.get_srcComponent() != self.state.compid:
            return
        self.state = replace(self.state, last_heartbeat_s=self._clock.now(), armed=bool(msg.base_mode & 128),
                             custom_mode=msg.custom_mode, system_status=msg.system_status)
        if self._key_to_give is not None:
            self._give_key(self._key_to_give, signed_heartbeat=bool(getattr(msg, "_signed", False)))

    def _give_key(self, key: bytes, signed_heartbeat: bool) -> None:
        """SETUP_SIGNING (signed with the key: a vehicle without one accepts anything) until the vehicle signs."""
        if signed_heartbeat:
            log.info("the vehicle signs with our key")
            self._key_to_give = None
            return
        sysid, compid = self._target()
        self._mav.setup_signing_send(sysid, compid, list(key), wall_timestamp())

    def _on_boot_time(self, boot_s: float) -> None:
        """Track the vehicle's time since boot; when it goes back, the vehicle restarted: forget what we knew of the
        flight before (a restarted PX4 is disarmed, its position and home are new) and count the restart."""
        st = self.state
        if st.boot_s is not None and boot_s < st.boot_s - RESTART_STEP_S:
            log.info("vehicle restarted: time since boot went from %.3f s to %.3f s", st.boot_s, boot_s)
            st = replace(VehicleState(), sysid=st.sysid, compid=st.compid, last_heartbeat_s=st.last_heartbeat_s,
                         custom_mode=st.custom_mode, system_status=st.system_status, restarts=st.restarts + 1,
                         uptime_before_restart_s=st.boot_s)
        latest = boot_s if st.boot_s is None else max(st.boot_s, boot_s)
        self.state = replace(st, boot_s=latest, stamped_s=self._clock.now())

    def _on_local_position(self, msg: Any) -> None:
        self.state = replace(self.state, pos_ned_m=(msg.x, msg.y, msg.z), vel_ned_m_s=(msg.vx, msg.vy, msg.vz))

    def _on_attitude(self, msg: Any) -> None:
        self.state = replace(self.state, yaw_rad=msg.yaw)

    def _on_extended_sys_state(self, msg: Any) -> None:
        self.state = replace(self.state, landed_state=msg.landed_state)

    def _on_home(self, msg: Any) -> None:
        self.state = replace(self.state, home_ned_m=(msg.x, msg.y, msg.z))

    def _on_ack(self, msg: Any) -> None:
        if getattr(msg, "target_system", 0) not in (0, GCS_SYSID):
            return  # an answer to another client on the same link
        for handle in self._pending:
            if handle.command == msg.command:
                handle.result = msg.result
        self._pending = [h for h in self._pending if not h.done]

    def _on_statustext(self, msg: Any) -> None:
        text = msg.text if isinstance(msg.text, str) else msg.text.decode(errors="replace")
        chunk_id = getattr(msg, "id", 0)
        if chunk_id:  # PX4 splits texts over 50 characters into chunks sharing an id (streams/STATUSTEXT.hpp)
            self._chunks[chunk_id] = self._chunks.get(chunk_id, "") + text
            if len(text) >= 50:
                return
            text = self._chunks.pop(chunk_id)
        status = StatusText(self._clock.now(), msg.severity, text.strip())
        self.statustexts.append(status)
        self._unread.append(status)

    def take_new_statustexts(self) -> list[StatusText]:
        """The STATUSTEXTs that arrived since the last call."""
        texts, self._unread = self._unread, []
        return texts

    # --- sending ---------------------------------------------------------------------------------------------
    def tick(self) -> None:
        """Send the 1 Hz heartbeat and retransmit unanswered commands."""
        now = self._clock.now()
        if self._signing:
            keep_up(self._mav)
        if now >= self._next_heartbeat_s:
            self._mav.heartbeat_send(MAV_TYPE_GCS, MAV_AUTOPILOT_INVALID, 0, 0, 4)  # system_status ACTIVE
            self._next_heartbeat_s = now + HEARTBEAT_PERIOD_S
        for handle in self._pending:
            if handle.result is None and now - handle.sent_at_s >= COMMAND_TIMEOUT_S:
                if handle.transmissions >= COMMAND_TRANSMISSIONS:
                    handle.timed_out = True
                    continue
                self._send_command(handle.command, handle.params, confirmation=handle.transmissions)
                handle.transmissions += 1
                handle.sent_at_s = now
        self._pending = [h for h in self._pending if not h.done]

    def _target(self) -> tuple[int, int]:
        return self.state.sysid or 1, self.state.compid or 1

    def _send_command(self, command: int, params: tuple[float, ...], confirmation: int = 0) -> None:
        sysid, compid = self._target()
        self._mav.send(self._mav.command_long_encode(sysid, compid, command, confirmation, *params))

    def command(self, command: int, *params: float) -> CommandHandle:
        """Send a COMMAND_LONG (unused params 0, which PX4 accepts in every version) and track its ACK."""
        full = tuple(params) + (0.0,) * (7 - len(params))
        handle = CommandHandle(command, full, self._clock.now())
        self._pending.append(handle)  # an ACK answers every pending handle of its command
        self._send_command(command, full)
        return handle

    def arm(self, arm: bool = True) -> CommandHandle:
        return self.command(mavlink2.MAV_CMD_COMPONENT_ARM_DISARM, 1.0 if arm else 0.0)

    def set_mode(self, main: int, sub: int = 0) -> CommandHandle:
        """MAV_CMD_DO_SET_MODE: param1 = custom-mode flag (|armed), param2 = main mode, param3 = sub mode, as MAVSDK
        does for PX4 (core/system_impl.cpp make_command_px4_mode)."""
        base = 1 | (128 if self.state.armed else 0)
        return self.command(mavlink2.MAV_CMD_DO_SET_MODE, float(base), float(main), float(sub))

    def land(self) -> CommandHandle:
        return self.command(mavlink2.MAV_CMD_NAV_LAND)

    def return_to_launch(self) -> CommandHandle:
        return self.command(mavlink2.MAV_CMD_NAV_RETURN_TO_LAUNCH)

    def request_home(self) -> CommandHandle:
        return self.command(mavlink2.MAV_CMD_REQUEST_MESSAGE, float(mavlink2.MAVLINK_MSG_ID_HOME_POSITION))

    def send_setpoint(self, sp: Setpoint) -> None:
        """SET_POSITION_TARGET_LOCAL_NED in LOCAL_NED: position + yaw, with velocity feed-forward if it has one."""
        sysid, compid = self._target()
        vx, vy, vz = sp.vel_ned_m_s if sp.vel_ned_m_s is not None else (0.0, 0.0, 0.0)
        x, y, z = sp.pos_ned_m
        boot_ms = int((self._clock.now() - self._t0_s) * 1000) & 0xFFFFFFFF
        self._mav.set_position_target_local_ned_send(boot_ms, sysid, compid, FRAME_LOCAL_NED, sp.type_mask,
                                                     x, y, z, vx, vy, vz, 0.0, 0.0, 0.0, sp.yaw_rad, 0.0)

    def send_manual_control(self, x: int, y: int, z: int, r: int) -> None:
        """MANUAL_CONTROL to the vehicle, as QGroundControl's joystick sends it: x forward (pitch), y right (roll), r
        yaw in -1000..1000, z throttle 0..1000 (500 centred); no buttons (PX4's multicopter modes use none)."""
        self._mav.manual_control_send(self._target()[0], x, y, z, r, 0)

    def close(self) -> None:
        self.transport.close()


_HANDLERS = {
    "LOCAL_POSITION_NED": VehicleLink._on_local_position,
    "ATTITUDE": VehicleLink._on_attitude,
    "EXTENDED_SYS_STATE": VehicleLink._on_extended_sys_state,
    "HOME_POSITION": VehicleLink._on_home,
    "COMMAND_ACK": VehicleLink._on_ack,
    "STATUSTEXT": VehicleLink._on_statustext,
}
