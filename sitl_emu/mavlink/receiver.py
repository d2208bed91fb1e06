"""Messages the mavlink receiver itself handles: commands, modes, offboard setpoints, manual control, heartbeat, ping,
timesync.

Sources: src/modules/mavlink/mavlink_receiver.cpp (handle_message_command_long/int/both ~l.493-930, set_mode ~l.1061,
heartbeat, ping ~l.1912), mavlink_timesync.cpp; reference 1.8-1.10, 3.1, 3.4, 4.4, 4.7, 4.8.
Command routing as mavlink_receiver.cpp evaluate_target_ok() codes it (every version up to v1.17): a command is ours
iff target_system is exactly our sysid and target_component is our compid or 0; only REQUEST_AUTOPILOT_CAPABILITIES
and REQUEST_PROTOCOL_VERSION also accept target_system 0 and any component. Anything else is ignored without an ACK.
(Reference 3.1 says target_system 0 is accepted for all commands; the code says otherwise, and PX4 is right.)
Offboard setpoints do accept target_system 0. A command that sets a param its MAV_CMD does not take is DENIED before
anything else sees it (PX4 main's mavlink_command_params.hpp; protocols/command_params.py).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from sitl_emu.mavlink import setpoints
from sitl_emu.mavlink.link_commands import ANY_COMPONENT, CommandHandler
from sitl_emu.mavlink.protocols.command_params import command_carries_unused_param
from sitl_emu.px4 import MavCmd, MavResult, Severity, decode_custom_mode
from sitl_emu.types import FollowTargetSample, ManualControlSetpoint, VehicleCommand

if TYPE_CHECKING:
    from typing import TypeAlias

    from pymavlink.dialects.v20 import development as dialect
    from pymavlink.dialects.v20.development import MAVLink_message

    from sitl_emu.mavlink.context import EndpointContext

    _CommandMessage: TypeAlias = dialect.MAVLink_command_long_message | dialect.MAVLink_command_int_message

log = logging.getLogger(__name__)

MAV_TYPE_GCS = 6
# COMMAND_LONG param5 and param6 within one float32 ulp of INT32_MAX: "INT32_MAX sent in a COMMAND_LONG" -> DENIED
INT32_MAX_LO, INT32_MAX_HI = float(2**31 - 128), float(2**31 + 256)  # nextafterf((float)INT32_MAX, 0 / +inf)
COMMAND_INT_NAN_XY = 0x7FF80000  # x == y == this: DENIED (reference 3.1)
INT32_MAX = 2**31 - 1
ERROR_TEXT_INTERVAL_US = 1_000_000  # one copy of the same complaint per second, so a flood cannot flood the log


class Receiver:
    """One per link; `handle(msg, ctx)` for every message (it ignores types it does not know). Commands go on to
    the link's CommandHandler."""

    def __init__(self, commands: CommandHandler) -> None:
        self._commands = commands
        # message type -> its handler, which takes that type's message class (the one place a message is narrowed)
        self._table: dict[str, Callable[[Any, EndpointContext], None]] = {
            "HEARTBEAT": self._heartbeat,
            "COMMAND_LONG": self._command_long,
            "COMMAND_INT": self._command_int,
            "SET_MODE": self._set_mode,
            "SET_POSITION_TARGET_LOCAL_NED": self._local_ned,
            "SET_POSITION_TARGET_GLOBAL_INT": self._global_int,
            "SET_ATTITUDE_TARGET": self._attitude_target,
            "MANUAL_CONTROL": self._manual_control,
            "FOLLOW_TARGET": self._follow_target,
            "PING": self._ping,
            "TIMESYNC": self._timesync,
        }
        self._last_error_us: dict[str, int] = {}
        self.setpoints_accepted = 0
        self.setpoints_refused = 0

    def handle(self, msg: MAVLink_message, ctx: EndpointContext) -> None:
        fn = self._table.get(msg.get_type())
        if fn is not None:
            fn(msg, ctx)

    # --- bookkeeping -------------------------------------------------------------------------------------------
    @staticmethod
    def _heartbeat(msg: dialect.MAVLink_heartbeat_message, ctx: EndpointContext) -> None:
        if msg.type == MAV_TYPE_GCS and msg.get_srcSystem() != ctx.sysid:
            ctx.last_gcs_heartbeat_us = ctx.now_us
            ctx.vehicle.gcs_heartbeat()  # the commander's data-link watchdog (COM_DL_LOSS_T)

    @staticmethod
    def _ping(msg: dialect.MAVLink_ping_message, ctx: EndpointContext) -> None:
        """Echo pings addressed to everyone (target 0/0), back to the sender (reference 1.9)."""
        if msg.target_system == 0 and msg.target_component == 0:
            ctx.send(ctx.encoder.ping_encode(msg.time_usec, msg.seq, msg.get_srcSystem(), msg.get_srcComponent()))

    @staticmethod
    def _timesync(msg: dialect.MAVLink_timesync_message, ctx: EndpointContext) -> None:
        """mavlink_timesync.cpp: answer requests (tc1 == 0) with our boot time in ns."""
        if msg.tc1 == 0:
            ctx.send(ctx.encoder.timesync_encode(ctx.now_us * 1000, msg.ts1))

    # --- commands ----------------------------------------------------------------------------------------------
    def _command_long(self, msg: dialect.MAVLink_command_long_message, ctx: EndpointContext) -> None:
        if not _command_for_us(msg, ctx):
            return
        params = (msg.param1, msg.param2, msg.param3, msg.param4, msg.param5, msg.param6, msg.param7)
        cmd = _command(msg, params)
        int32_max_position = _is_int32_max(msg.param5) and _is_int32_max(msg.param6)
        if int32_max_position or command_carries_unused_param(cmd.command, cmd.params):
            _ack_here(ctx, cmd, MavResult.DENIED)
            return
        self._commands.execute(cmd, ctx)

    def _command_int(self, msg: dialect.MAVLink_command_int_message, ctx: EndpointContext) -> None:
        if not _command_for_us(msg, ctx):
            return
        x, y = int(msg.x), int(msg.y)
        if x == COMMAND_INT_NAN_XY and y == COMMAND_INT_NAN_XY:
            _ack_here(ctx, _command(msg, (msg.param1, msg.param2, msg.param3, msg.param4, 0.0, 0.0, msg.z)),
                      MavResult.DENIED)
            return
        p5, p6 = _command_int_xy(x, y)
        cmd = _command(msg, (msg.param1, msg.param2, msg.param3, msg.param4, p5, p6, msg.z))
        if command_carries_unused_param(cmd.command, cmd.params):
            _ack_here(ctx, cmd, MavResult.DENIED)
            return
        self._commands.execute(cmd, ctx)

    def _set_mode(self, msg: dialect.MAVLink_set_mode_message, ctx: EndpointContext) -> None:
        """SET_MODE -> DO_SET_MODE(base_mode, main, sub); the ACK is for command 176 (reference 3.4)."""
        if msg.target_system != ctx.sysid:  # commander only takes DO_SET_MODE meant exactly for this system
            return
        main, sub = decode_custom_mode(msg.custom_mode)
        cmd = VehicleCommand(MavCmd.DO_SET_MODE, (float(msg.base_mode), float(main), float(sub), 0.0, 0.0, 0.0, 0.0),
                             msg.get_srcSystem(), msg.get_srcComponent(), True)
        self._commands.execute(cmd, ctx)

    # --- offboard setpoints ------------------------------------------------------------------------------------
    def _local_ned(self, msg: dialect.MAVLink_set_position_target_local_ned_message, ctx: EndpointContext) -> None:
        if _targets_us(msg, ctx):
            self._apply(setpoints.decode_local_ned(msg, ctx.node.snapshot()), ctx)

    def _global_int(self, msg: dialect.MAVLink_set_position_target_global_int_message, ctx: EndpointContext
                    ) -> None:
        if _targets_us(msg, ctx):
            self._apply(setpoints.decode_global_int(msg, ctx.node.snapshot()), ctx)

    def _attitude_target(self, msg: dialect.MAVLink_set_attitude_target_message, ctx: EndpointContext) -> None:
        if _targets_us(msg, ctx):
            self._apply(setpoints.decode_attitude_target(msg), ctx)

    # --- manual control (a MAVLink joystick) ---------------------------------------------------------------------
    @staticmethod
    def _manual_control(msg: dialect.MAVLink_manual_control_message, ctx: EndpointContext) -> None:
        """handle_message_manual_control: for target 0 or our system; the vehicle decides whether it uses it
        (COM_RC_IN_MODE)."""
        if msg.target in (0, ctx.sysid):
            ctx.vehicle.manual_control_input(manual_setpoint(msg.x, msg.y, msg.z, msg.r, msg.buttons))
            ctx.node.invalidate_snapshot()

    # --- follow target ----------------------------------------------------------------------------------------
    @staticmethod
    def _follow_target(msg: dialect.MAVLink_follow_target_message, ctx: EndpointContext) -> None:
        """handle_message_follow_target: from anyone (no target fields), stamped on receipt, lat/lon degE7, alt
        AMSL, vel NED. SAFER THAN PX4: a fix off the globe (|lat| > 90 deg, |lon| > 180 deg) is dropped; PX4 would
        project it somewhere on Earth and fly there. NaN altitude or velocity is passed on: the estimator refuses it
        as PX4's does."""
        lat, lon = msg.lat * 1e-7, msg.lon * 1e-7
        if abs(lat) > 90.0 or abs(lon) > 180.0:
            return
        vel = (float(msg.vel[0]), float(msg.vel[1]), float(msg.vel[2]))
        ctx.vehicle.follow_target_input(FollowTargetSample(ctx.now_us, lat, lon, float(msg.alt), vel))
        ctx.node.invalidate_snapshot()

    def _apply(self, decoded: setpoints.Decoded, ctx: EndpointContext) -> None:
        if decoded.mode is None:
            self.setpoints_refused += 1
            if decoded.error is not None:
                self._complain(decoded.error, ctx)
            return
        self.setpoints_accepted += 1
        ctx.vehicle.offboard_input(decoded.mode, decoded.trajectory, decoded.attitude)
        ctx.node.invalidate_snapshot()

    def _complain(self, text: str, ctx: EndpointContext) -> None:
        last = self._last_error_us.get(text)
        if last is not None and ctx.now_us - last < ERROR_TEXT_INTERVAL_US:
            return
        self._last_error_us[text] = ctx.now_us
        ctx.vehicle.report(Severity.CRITICAL, "mavlink", text, is_event=True)


def manual_setpoint(x: int, y: int, z: int, r: int, buttons: int) -> ManualControlSetpoint:
    """MANUAL_CONTROL's x (forward), y (right), r (yaw) in -1000..1000 and z (throttle) in 0..1000 as PX4 reads them
    into manual_control_setpoint: pitch x/1000, roll y/1000, yaw r/1000, throttle z/500 - 1 (500 is the centre).
    A field outside its range counts as 0, as in PX4: the stick centred, and for z the throttle centred, not low."""
    return ManualControlSetpoint(roll=_in_range(y, -1000, 1000) / 1000.0, pitch=_in_range(x, -1000, 1000) / 1000.0,
                                 yaw=_in_range(r, -1000, 1000) / 1000.0,
                                 throttle=_in_range(z, 0, 1000, 500) / 500.0 - 1.0, buttons=int(buttons) & 0xFFFF)


def _in_range(value: int, lo: int, hi: int, otherwise: int = 0) -> int:
    return value if lo <= value <= hi else otherwise


def _targets_us(msg: setpoints.SetpointMessage, ctx: EndpointContext) -> bool:
    """Setpoint messages: target_system 0 or ours, target_component 0 or ours."""
    return msg.target_system in (0, ctx.sysid) and msg.target_component in (0, ctx.compid)


def _command_for_us(msg: _CommandMessage, ctx: EndpointContext) -> bool:
    """evaluate_target_ok(): exact sysid for commands, except the two legacy broadcast requests."""
    if msg.command in ANY_COMPONENT:
        return msg.target_system in (0, ctx.sysid)
    return msg.target_system == ctx.sysid and msg.target_component in (0, ctx.compid)


def _command(msg: _CommandMessage, params: tuple[float, ...]) -> VehicleCommand:
    values = tuple(float(p) for p in params)
    return VehicleCommand(int(msg.command), values, msg.get_srcSystem(), msg.get_srcComponent(), True)  # type: ignore[arg-type]


def _ack_here(ctx: EndpointContext, cmd: VehicleCommand, result: int) -> None:
    ctx.send(ctx.encoder.command_ack_encode(cmd.command, result, 0, 0, cmd.source_system, cmd.source_component))


def _is_int32_max(value: float) -> bool:
    return INT32_MAX_LO <= value <= INT32_MAX_HI


def _command_int_xy(x: int, y: int) -> tuple[float, float]:
    """COMMAND_INT x/y -> param5/6 as PX4 <= v1.17 does: both INT32_MAX means "not set" (NaN), else x/1e7, y/1e7.

    (PX4 main later scales by frame, /1e4 for local frames and raw for non-location commands; v1.15-v1.17 do not.)
    """
    if x == INT32_MAX and y == INT32_MAX:
        return math.nan, math.nan
    return x / 1e7, y / 1e7
