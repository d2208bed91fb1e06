"""Health and status messages: SYS_STATUS, the estimator's reports, mission progress, RTL time, link statistics.

Each builder follows the PX4 stream of the same name (src/modules/mavlink/streams/<NAME>.hpp); where the data comes
from a PX4 module the emulator does not run (EKF2, the logger, the RTL time estimator), the values are what PX4 SIH
reports for a vehicle in the same state, as described at each builder.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Final

from sitl_emu.mavlink.protocols.mission_items import mission_current_fields
from sitl_emu.mavlink.telemetry.messages import UINT16_MAX
from sitl_emu.mavlink.wire.extra_messages import EXTRA
from sitl_emu.types import VehicleSnapshot

if TYPE_CHECKING:
    from sitl_emu.mavlink.context import EndpointContext, OutMessage

# MAV_SYS_STATUS_SENSOR bits (common.xml)
S_GYRO, S_ACCEL, S_MAG, S_ABS_PRESSURE, S_DIFF_PRESSURE, S_GPS = 0x01, 0x02, 0x04, 0x08, 0x10, 0x20
S_ATTITUDE_STAB, S_XY_POSITION, S_MOTOR_OUTPUTS, S_RC = 0x800, 0x4000, 0x8000, 0x10000
S_AHRS, S_LOGGING, S_BATTERY, S_PREARM_CHECK = 0x200000, 0x1000000, 0x2000000, 0x10000000
S_EXT_RECOVERY_SYSTEM: Final = 0x1  # MAV_SYS_STATUS_SENSOR_EXTENDED

# The components SYS_STATUS.hpp reports (fillOutComponent: battery, motors/ESCs, accel, gyro, mag, GPS, RC, attitude
# estimate as ATTITUDE_STABILIZATION and AHRS, local position as XY_POSITION_CONTROL, logging, absolute and
# differential pressure). Each is healthy unless commander's health report has an error or warning for it, present
# or not; enabled when present or unhealthy (required but missing).
REPORTED: Final = (S_BATTERY | S_MOTOR_OUTPUTS | S_ACCEL | S_GYRO | S_MAG | S_GPS | S_RC | S_ATTITUDE_STAB
                   | S_XY_POSITION | S_AHRS | S_LOGGING | S_ABS_PRESSURE | S_DIFF_PRESSURE)
# What PX4 SIH has: simulated IMU, magnetometer, barometer and GPS, the battery simulator, the logger, the motor
# outputs and EKF2's local position. No RC, no airspeed sensor; the attitude estimate reports no presence.
PRESENT_SIH: Final = (S_GYRO | S_ACCEL | S_MAG | S_ABS_PRESSURE | S_GPS | S_XY_POSITION | S_MOTOR_OUTPUTS | S_LOGGING
                      | S_BATTERY)
# Unhealthy until the estimator has converged: GPS checks, the attitude estimate and the local position.
_ESTIMATOR_BITS: Final = S_GPS | S_ATTITUDE_STAB | S_AHRS | S_XY_POSITION


def sensor_bits(snap: VehicleSnapshot) -> tuple[int, int, int]:
    """(present, enabled, health) of SYS_STATUS, as PX4 SIH reports them (at rest and ready: 0x0300c02f,
    0x0301c02f, 0x1320c83f).

    Remote control (a MAVLink joystick here) is present and healthy while manual control is valid; without it
    rcAndDataLinkCheck.cpp reports "No manual control input" on the remote_control component: unhealthy, enabled.
    PREARM_CHECK is set when arming is possible in the mode in force (health_report.can_arm_mode_flags), which stays
    true armed (the mode-prevents-arming check is skipped while armed) and through a Return failsafe; arming checks
    that fail clear it.
    """
    present = PRESENT_SIH | (S_RC if snap.manual_control else 0)
    faults = 0 if snap.manual_control else S_RC
    if not snap.position_valid:
        faults |= _ESTIMATOR_BITS
    health = REPORTED & ~faults
    if snap.pre_flight_checks_pass:
        health |= S_PREARM_CHECK
    enabled = present | (REPORTED & ~health)
    return present, enabled, health


def sys_status(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    """streams/SYS_STATUS.hpp; MAVSDK reads health from these bits (reference 9a.5). The parachute (recovery system,
    an extended bit) has no fault, so it reads healthy, neither present nor enabled."""
    present, enabled, health = sensor_bits(snap)
    voltage_mv = int(min(max(snap.battery_voltage_v * 1000.0, 0.0), UINT16_MAX - 1))
    level = snap.battery_remaining
    remaining = math.ceil(min(max(level, 0.0), 1.0) * 100.0) if math.isfinite(level) else -1
    return ctx.encoder.sys_status_encode(present, enabled, health, 0, voltage_mv, -1, remaining, 0, 0, 0, 0, 0, 0,
                                         0, 0, S_EXT_RECOVERY_SYSTEM)


# ESTIMATOR_STATUS_FLAGS (common.xml)
E_ATTITUDE, E_VEL_HORIZ, E_VEL_VERT, E_POS_HORIZ_REL, E_POS_HORIZ_ABS = 1, 2, 4, 8, 16
E_POS_VERT_ABS, E_POS_VERT_AGL, E_CONST_POS_MODE, E_PRED_POS_HORIZ_REL, E_PRED_POS_HORIZ_ABS = 32, 64, 128, 256, 512
# EKF2 on SIH once GPS is fused (Ekf::get_ekf_soln_status): attitude, GPS velocity and position, baro height, and a
# terrain estimate from the simulated range finder (EKF2_RNG_CTRL 1): 895.
EKF_FLAGS_READY: Final = (E_ATTITUDE | E_VEL_HORIZ | E_VEL_VERT | E_POS_HORIZ_REL | E_POS_HORIZ_ABS | E_POS_VERT_ABS
                          | E_POS_VERT_AGL | E_PRED_POS_HORIZ_REL | E_PRED_POS_HORIZ_ABS)
# Before that: attitude and baro height only, horizontally in constant-position mode.
EKF_FLAGS_ALIGNING: Final = E_ATTITUDE | E_VEL_VERT | E_POS_VERT_ABS | E_CONST_POS_MODE
# Innovation test ratios and accuracies (m) of EKF2 on SIH's low-noise simulated sensors: small fractions of the gates.
EKF_TEST_RATIOS: Final = (0.02, 0.01, 0.04, 0.02, 0.01, 0.0)  # velocity, horiz. pos, vert. pos, mag, HAGL, airspeed
EKF_ACCURACY_M: Final = (0.3, 0.4)  # horizontal, vertical


def estimator_status(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    """streams/ESTIMATOR_STATUS.hpp: estimator_status.solution_status_flags, test ratios and accuracies."""
    flags = EKF_FLAGS_READY if snap.position_valid else EKF_FLAGS_ALIGNING
    return ctx.encoder.estimator_status_encode(snap.time_us, flags, *EKF_TEST_RATIOS, *EKF_ACCURACY_M)


# ESTIMATOR_SENSOR_FUSION_STATUS sources, index = source - 1: GPS, optical flow, vision, aux. global position, baro,
# range finder, magnetometer, airspeed, ranging beacon.
# SIH defaults: EKF2_GPS_CTRL 7, EKF2_OF_CTRL 1, EKF2_BARO_CTRL 1, EKF2_RNG_CTRL 1, EKF2_MAG_TYPE 0 (automatic)
_FUSION_INTENDED: Final = (1, 1, 0, 0, 1, 1, 1, 0, 0)
_FUSION_ACTIVE: Final = (1, 0, 0, 0, 1, 1, 1, 0, 0)  # no flow sensor in SIH
_FUSION_ACTIVE_ALIGNING: Final = (0, 0, 0, 0, 1, 1, 1, 0, 0)
_NAN9: Final = (math.nan,) * 9


def estimator_sensor_fusion_status(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    """streams/ESTIMATOR_SENSOR_FUSION_STATUS.hpp (not in pymavlink: extra_messages.py): per source, the instances
    EKF2 intends to fuse and those it fuses; the test ratios are NaN, as PX4 sends them."""
    active = _FUSION_ACTIVE if snap.position_valid else _FUSION_ACTIVE_ALIGNING
    return EXTRA.estimator_sensor_fusion_status_encode(_FUSION_INTENDED, active, _NAN9)


def mission_current(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    """mavlink_mission.cpp send_mission_current, about once a second on every link: the stored mission's current item
    and count (total UINT16_MAX with none), its state (NO_MISSION, or NOT_STARTED while stored and not flown) and
    whether the vehicle is in a mode that flies it (mission_items.mission_current_fields). The plan ids (a CRC32 per
    plan) are extension fields pymavlink lacks, so they are not on the wire."""
    return ctx.encoder.mission_current_encode(*mission_current_fields(ctx.vehicle.mission_store(), snap.nav_state))


# RTL time estimate (navigator's RtlTimeEstimator) with PX4's multicopter defaults: return altitude RTL_RETURN_ALT
# 30 m above home, climb MPC_Z_V_AUTO_UP 3 m/s, cruise MPC_XY_CRUISE 5 m/s, descend MPC_Z_V_AUTO_DN 1.5 m/s to
# RTL_DESCEND_ALT 10 m, land MPC_LAND_SPEED 0.7 m/s; safe estimate = RTL_TIME_FACTOR 1.1 x estimate +
# RTL_TIME_MARGIN 100 s.
_RTL_UP_M, _CLIMB, _CRUISE, _DESCEND, _DESCEND_ALT_M, _LAND = 30.0, 3.0, 5.0, 1.5, 10.0, 0.7
_TIME_FACTOR, _TIME_MARGIN_S = 1.1, 100.0


def rtl_time_estimate_s(snap: VehicleSnapshot) -> float:
    """Seconds a Return would take from here, with PX4's safety factor and margin; on the ground RTL has nothing to
    fly (the margin alone); -1 without home."""
    home = snap.home
    if home is None:
        return -1.0
    if snap.landed_state == 1:  # ON_GROUND
        return _TIME_MARGIN_S
    up, home_up = -snap.pos_ned_m[2], -home.pos_ned_m[2]
    return_up = max(up, home_up + _RTL_UP_M)
    dist = math.hypot(snap.pos_ned_m[0] - home.pos_ned_m[0], snap.pos_ned_m[1] - home.pos_ned_m[1])
    above = return_up - home_up
    seconds = ((return_up - up) / _CLIMB + dist / _CRUISE + max(above - _DESCEND_ALT_M, 0.0) / _DESCEND
               + min(above, _DESCEND_ALT_M) / _LAND)
    return _TIME_FACTOR * seconds + _TIME_MARGIN_S


def time_estimate_to_target(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    """streams/TIME_ESTIMATE_TO_TARGET.hpp (not in pymavlink: extra_messages.py): the safe RTL time; the other
    estimates are not supported by PX4 (-1). Sent when rtl_time_estimate updates (every 2 s: streams.py)."""
    safe = rtl_time_estimate_s(snap)
    return EXTRA.time_estimate_to_target_encode(int(safe) if math.isfinite(safe) else -1, -1, -1, -1, -1)


def link_node_status(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    """streams/LINK_NODE_STATUS.hpp (not in pymavlink: extra_messages.py): this link's counters (telemetry_status).
    Buffer levels are not reported (PX4: TODO, 0); losses and overflows are not tracked here (0)."""
    stats = ctx.stats
    tx_rate, rx_rate = stats.link_rates(snap.time_us)
    return EXTRA.link_node_status_encode(snap.time_us, 0, 0, tx_rate, rx_rate, stats.rx_parse_errors & 0xFFFF, 0, 0,
                                         stats.tx_messages & 0xFFFFFFFF, stats.rx_messages & 0xFFFFFFFF, 0)
