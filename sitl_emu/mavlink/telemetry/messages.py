"""Telemetry message builders: VehicleSnapshot -> one MAVLink message, or None when PX4 would have no data to send.

Each builder follows the PX4 stream of the same name (src/modules/mavlink/streams/<NAME>.hpp); the fields we do not
simulate carry the value PX4 uses for "unknown" (NaN, -1, UINT16_MAX...).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING, Final

from sitl_emu import px4
from sitl_emu.control.qmath import atan2, degrees, hypot, isfinite
from sitl_emu.mavlink.telemetry.fields import (
    INT16_MAX,
    INT32_MAX,
    INT32_MIN,
    clamp_int,
    cm_s,
    e7,
    iround,
    itrunc,
    mm,
    time_boot_ms,
)
from sitl_emu.mavlink.telemetry.modes import STANDARD_MODE
from sitl_emu.px4 import MavFrame, MavState, NavState
from sitl_emu.types import VehicleSnapshot

if TYPE_CHECKING:
    from sitl_emu.mavlink.context import EndpointContext, OutMessage

NAN = math.nan
UINT16_MAX: Final = 0xFFFF

# ODOMETRY's pose and velocity covariances: unknown (a NaN first element), as ODOMETRY.hpp sends them. Typed as a
# tuple of any length: compiled, a fixed-length float tuple would be unboxed and boxed again at every read.
ODOMETRY_COVARIANCE: tuple[float, ...] = (NAN,) + (0.0,) * 20

MAV_TYPE_QUADROTOR: Final = 2
MAV_AUTOPILOT_PX4: Final = 12

# Modes whose control mode has flag_control_manual_enabled and attitude (ModeUtil/control_mode.cpp).
_MANUAL_STABILIZED = frozenset({NavState.MANUAL, NavState.ALTCTL, NavState.POSCTL, NavState.POSITION_SLOW,
                                NavState.ALTITUDE_CRUISE, NavState.STAB})
# flag_control_auto_enabled: the AUTO.* modes and Descend. Follow Target and Orbit are neither auto nor manual
# (control_mode.cpp: they accept stick adjustments), only attitude-stabilized.
_AUTO_CONTROL = px4.AUTO_MODES - {NavState.AUTO_FOLLOW_TARGET}
_STABILIZED_ONLY = frozenset({NavState.AUTO_FOLLOW_TARGET, NavState.ORBIT})

# A stream: the message for this snapshot, or None when PX4 would have no data to send
Builder = Callable[["EndpointContext", VehicleSnapshot], "OutMessage | None"]


def base_mode(snap: VehicleSnapshot) -> int:
    """HEARTBEAT.base_mode as streams/HEARTBEAT.hpp builds it from the control-mode flags (reference 2.2).

    OFFBOARD's flags come from the last offboard_control_mode commander received, however old (it keeps the last
    message): 17 once position, velocity, acceleration or attitude setpoints have been sent, 1 before any or with body
    rates only; armed adds 128.
    """
    nav = snap.nav_state
    flags = px4.MODE_FLAG_CUSTOM_MODE_ENABLED
    if nav in _MANUAL_STABILIZED:
        flags |= px4.MODE_FLAG_MANUAL_INPUT_ENABLED | px4.MODE_FLAG_STABILIZE_ENABLED
    elif nav == NavState.ACRO:
        flags |= px4.MODE_FLAG_MANUAL_INPUT_ENABLED
    elif nav in _AUTO_CONTROL:
        flags |= px4.MODE_FLAG_AUTO_ENABLED | px4.MODE_FLAG_GUIDED_ENABLED | px4.MODE_FLAG_STABILIZE_ENABLED
    elif nav == NavState.OFFBOARD:
        ocm = snap.offboard_control_last
        if ocm is not None and (ocm.position or ocm.velocity or ocm.acceleration or ocm.attitude):
            flags |= px4.MODE_FLAG_STABILIZE_ENABLED
    elif nav in _STABILIZED_ONLY:
        flags |= px4.MODE_FLAG_STABILIZE_ENABLED
    if snap.armed:
        flags |= px4.MODE_FLAG_SAFETY_ARMED
    return flags


def system_status(snap: VehicleSnapshot) -> int:
    """HEARTBEAT.system_status (reference 2.4)."""
    if snap.nav_state == NavState.TERMINATION:
        return MavState.FLIGHT_TERMINATION
    if snap.armed:
        return MavState.CRITICAL if snap.failsafe else MavState.ACTIVE
    return MavState.STANDBY if snap.pre_flight_checks_pass else MavState.UNINIT


def heartbeat(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    return ctx.encoder.heartbeat_encode(MAV_TYPE_QUADROTOR, MAV_AUTOPILOT_PX4, base_mode(snap),
                                    px4.custom_mode(snap.nav_state), system_status(snap), 3)


def extended_sys_state(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    return ctx.encoder.extended_sys_state_encode(0, int(snap.landed_state))


def attitude(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    r, p, y = snap.euler_rad
    wx, wy, wz = snap.rates_frd_rad_s
    return ctx.encoder.attitude_encode(time_boot_ms(snap.time_us), r, p, y, wx, wy, wz)


def attitude_quaternion(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    w, x, y, z = snap.q_wxyz
    wx, wy, wz = snap.rates_frd_rad_s
    return ctx.encoder.attitude_quaternion_encode(time_boot_ms(snap.time_us), w, x, y, z, wx, wy, wz,
                                                  (0.0, 0.0, 0.0, 0.0))


def local_position_ned(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    x, y, z = snap.pos_ned_m
    vx, vy, vz = snap.vel_ned_m_s
    return ctx.encoder.local_position_ned_encode(time_boot_ms(snap.time_us), x, y, z, vx, vy, vz)


def global_position_int(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage | None:
    """streams/GLOBAL_POSITION_INT.hpp: only with a global position; relative_alt against home (reference 9a.6)."""
    if not snap.position_valid:
        return None
    vx, vy, vz = snap.vel_ned_m_s
    rel_m = snap.alt_amsl_m - snap.home.alt_amsl_m if snap.home is not None else snap.alt_amsl_m
    hdg_cdeg = iround(degrees(_wrap_2pi(snap.euler_rad[2])) * 100.0) % 36000
    return ctx.encoder.global_position_int_encode(
        time_boot_ms(snap.time_us), e7(snap.lat_deg), e7(snap.lon_deg), mm(snap.alt_amsl_m), mm(rel_m),
        cm_s(vx), cm_s(vy), cm_s(vz), hdg_cdeg)


def position_target_local_ned(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage | None:
    """streams/POSITION_TARGET_LOCAL_NED.hpp: the controller's setpoint, a type_mask bit for every NaN (ref 4.9)."""
    sp = snap.local_setpoint
    if sp is None:
        return None
    x, y, z = sp.position_ned_m
    vx, vy, vz = sp.velocity_ned_m_s
    ax, ay, az = sp.acceleration_ned_m_s2
    mask = (_unset(x, 1) | _unset(y, 2) | _unset(z, 4) | _unset(vx, 8) | _unset(vy, 16) | _unset(vz, 32)
            | _unset(ax, 64) | _unset(ay, 128) | _unset(az, 256) | _unset(sp.yaw_rad, 1024)
            | _unset(sp.yawspeed_rad_s, 2048))
    return ctx.encoder.position_target_local_ned_encode(time_boot_ms(snap.time_us), MavFrame.LOCAL_NED, mask,
                                                        x, y, z, vx, vy, vz, ax, ay, az, sp.yaw_rad,
                                                        sp.yawspeed_rad_s)


def _unset(value: float, bit: int) -> int:
    """A type_mask bit: set for a value that is not controlled (NaN; inf too)."""
    return 0 if isfinite(value) else bit


def attitude_target(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage | None:
    q = snap.attitude_setpoint_q_wxyz
    if q is None:
        return None
    wx, wy, wz = snap.rates_setpoint_rad_s
    return ctx.encoder.attitude_target_encode(time_boot_ms(snap.time_us), 0, q, wx, wy, wz, snap.thrust_setpoint)


def home_position(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage | None:
    """streams/HOME_POSITION.hpp: only while home is valid."""
    home = snap.home
    if home is None:
        return None
    half = home.yaw_rad / 2.0 if isfinite(home.yaw_rad) else NAN
    q = (math.cos(half), 0.0, 0.0, math.sin(half))
    x, y, z = home.pos_ned_m
    return ctx.encoder.home_position_encode(e7(home.lat_deg), e7(home.lon_deg), mm(home.alt_amsl_m), x, y, z, q,
                                        0.0, 0.0, 0.0, snap.time_us)


def gps_raw_int(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    """SIH's GPS (sensor_gps_sim): 3D fix, 10 satellites, from boot; no fix and no satellites while failed."""
    vn, ve, _ = snap.vel_ned_m_s
    vel_cm_s = min(iround(hypot(vn, ve) * 100.0), UINT16_MAX - 1)
    cog = iround(degrees(_wrap_2pi(atan2(ve, vn))) * 100.0) % 36000 if vel_cm_s > 0 else 0
    fix = snap.gps_fix_type
    return ctx.encoder.gps_raw_int_encode(snap.time_us, fix, e7(snap.lat_deg), e7(snap.lon_deg), mm(snap.alt_amsl_m),
                                      50, 80, vel_cm_s, cog, 10 if fix else 0, mm(snap.alt_amsl_m), 500, 800, 200, 0,
                                      0)


def battery_status(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    cells = 4  # BAT1_N_CELLS in SITL
    cell_mv = int(min(snap.battery_voltage_v / cells * 1000.0, UINT16_MAX - 1))
    voltages = [cell_mv] * cells + [UINT16_MAX] * (10 - cells)
    remaining = iround(min(max(snap.battery_remaining, 0.0), 1.0) * 100.0)
    charge_state = min(max(snap.battery_warning, 0), 3) + 1  # BATTERY_STATUS.hpp: WARNING_* -> CHARGE_STATE_*
    return ctx.encoder.battery_status_encode(0, 1, 1, INT16_MAX, voltages, -1, -1, -1, remaining, 0, charge_state,
                                             [0, 0, 0, 0], 0, 0)


def vfr_hud(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    """streams/VFR_HUD.hpp (reference 11.5)."""
    vn, ve, vd = snap.vel_ned_m_s
    heading_deg = int(degrees(_wrap_2pi(snap.euler_rad[2]))) % 360
    throttle = iround(min(max(snap.thrust_setpoint, 0.0), 1.0) * 100.0) if snap.armed else 0
    return ctx.encoder.vfr_hud_encode(NAN, hypot(vn, ve), heading_deg, throttle, snap.alt_amsl_m, -vd)


def altitude(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    rel_m = snap.alt_amsl_m - snap.home.alt_amsl_m if snap.home is not None else NAN
    local_m = -snap.pos_ned_m[2]
    return ctx.encoder.altitude_encode(snap.time_us, snap.alt_amsl_m, snap.alt_amsl_m, local_m, rel_m, NAN,
                                   max(local_m, 0.0))


def odometry(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    """streams/ODOMETRY.hpp: pose in LOCAL_NED, velocity in the body FRD frame."""
    x, y, z = snap.pos_ned_m
    vx, vy, vz = rotate_ned_to_body(snap.q_wxyz, snap.vel_ned_m_s)
    wx, wy, wz = snap.rates_frd_rad_s
    return ctx.encoder.odometry_encode(snap.time_us, MavFrame.LOCAL_NED, MavFrame.BODY_FRD, x, y, z, snap.q_wxyz,
                                       vx, vy, vz, wx, wy, wz, ODOMETRY_COVARIANCE, ODOMETRY_COVARIANCE, 0, 1, 100)


def timesync(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    """streams/TIMESYNC.hpp: PX4's own sync request, tc1=0, ts1=boot time in ns."""
    return ctx.encoder.timesync_encode(0, snap.time_us * 1000)


def ping(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    """streams/PING.hpp: PX4 pings everyone (target 0/0) with its boot time and a sequence; replies are ignored."""
    seq = snap.time_us // 100_000  # unique per ping at any rate up to 10 Hz, from simulated time
    return ctx.encoder.ping_encode(snap.time_us, seq & 0xFFFFFFFF, 0, 0)


def system_time(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    return ctx.encoder.system_time_encode(ctx.node.epoch_unix_us + snap.time_us, time_boot_ms(snap.time_us))


def current_mode(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    return ctx.encoder.current_mode_encode(STANDARD_MODE.get(snap.nav_state, 0), px4.custom_mode(snap.nav_state),
                                       px4.custom_mode(snap.user_intended_nav_state))


def orbit_execution_status(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage | None:
    """ORBIT_EXECUTION_STATUS.hpp: only while the orbit task publishes orbit_status; frame 0 (MAV_FRAME_GLOBAL),
    x/y the centre in degE7 (the double times 1e7 stored in an int32: truncated), z the altitude AMSL."""
    o = snap.orbit
    if o is None:
        return None
    return ctx.encoder.orbit_execution_status_encode(o.time_us, o.radius_m, 0, _trunc_e7(o.lat_deg),
                                                     _trunc_e7(o.lon_deg), o.alt_amsl_m)


def _trunc_e7(deg: float) -> int:
    return clamp_int(itrunc(deg * 1e7), INT32_MIN, INT32_MAX)


def rotate_ned_to_body(q_wxyz: tuple[float, float, float, float], v: tuple[float, float, float]
                       ) -> tuple[float, float, float]:
    """v expressed in the body frame: R(q)^T v, with q rotating body to NED."""
    w, x, y, z = q_wxyz
    return _rotate((w, -x, -y, -z), v)


def rotate_body_to_ned(q_wxyz: tuple[float, float, float, float], v: tuple[float, float, float]
                       ) -> tuple[float, float, float]:
    return _rotate(q_wxyz, v)


def _rotate(q: tuple[float, float, float, float], v: tuple[float, float, float]) -> tuple[float, float, float]:
    w, x, y, z = q
    vx, vy, vz = v
    # t = 2 q_vec x v; v' = v + w t + q_vec x t
    tx, ty, tz = 2 * (y * vz - z * vy), 2 * (z * vx - x * vz), 2 * (x * vy - y * vx)
    return (vx + w * tx + (y * tz - z * ty), vy + w * ty + (z * tx - x * tz), vz + w * tz + (x * ty - y * tx))


def _wrap_2pi(a: float) -> float:
    return a % (2.0 * math.pi)
