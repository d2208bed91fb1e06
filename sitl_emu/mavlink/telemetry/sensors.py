"""Sensor-style telemetry derived from the vehicle's state: IMU, barometer, range finder, vibration, GNSS, Remote ID.

PX4 streams these from sensor_combined / vehicle_air_data (streams/HIGHRES_IMU.hpp, SCALED_PRESSURE.hpp); SIH's
sensors are the true state plus noise. We have no separate sensor model, so: accelerometer = specific force in FRD,
gyro = body rates, magnetometer = a fixed Earth field rotated into the body, barometer = ISA pressure at the altitude.
The range finder, the vibration metrics, GNSS integrity and Remote ID (OPEN_DRONE_ID_*) follow SIH's simulated
sensors as each builder says; their values are noise-free (the vibration metrics: what SIH's noise averages to).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Final

from sitl_emu.control.qmath import atan2, degrees, hypot, isfinite
from sitl_emu.mavlink.telemetry.fields import clamp_int, e7, iround, itrunc, time_boot_ms
from sitl_emu.mavlink.telemetry.messages import rotate_ned_to_body
from sitl_emu.types import Vec3, VehicleSnapshot

if TYPE_CHECKING:
    from sitl_emu.mavlink.context import EndpointContext, OutMessage

GRAVITY_M_S2: Final = 9.80665
# Earth magnetic field near the SIH default home (Zurich), gauss, NED: ~0.48 G, inclination ~63.5°, declination ~2.5°
MAG_NED_GAUSS = (0.214, 0.009, 0.430)
TEMPERATURE_C: Final = 20.0
HIGHRES_FIELDS_ALL: Final = 0x1FFF  # acc, gyro, mag, abs/diff pressure, pressure altitude, temperature


def isa_pressure_hpa(alt_amsl_m: float) -> float:
    """International Standard Atmosphere pressure at an altitude (troposphere)."""
    return 1013.25 * math.pow(1.0 - 2.25577e-5 * alt_amsl_m, 5.25588) if alt_amsl_m < 11000 else 226.32


def specific_force_frd(snap: VehicleSnapshot) -> tuple[float, float, float]:
    """What an accelerometer reads: (a - g) in the body frame; -9.81 on z at rest."""
    ax, ay, az = snap.acc_ned_m_s2
    return rotate_ned_to_body(snap.q_wxyz, (ax, ay, az - GRAVITY_M_S2))


def highres_imu(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    ax, ay, az = specific_force_frd(snap)
    wx, wy, wz = snap.rates_frd_rad_s
    mx, my, mz = rotate_ned_to_body(snap.q_wxyz, MAG_NED_GAUSS)
    pressure = isa_pressure_hpa(snap.alt_amsl_m)
    return ctx.encoder.highres_imu_encode(snap.time_us, ax, ay, az, wx, wy, wz, mx, my, mz, pressure, 0.0,
                                          snap.alt_amsl_m, TEMPERATURE_C, HIGHRES_FIELDS_ALL, 0)


def scaled_pressure(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage | None:
    pressure = isa_pressure_hpa(snap.alt_amsl_m)
    if not isfinite(pressure):
        return None
    return ctx.encoder.scaled_pressure_encode(time_boot_ms(snap.time_us), pressure, 0.0,
                                          round(TEMPERATURE_C * 100), 0)


# --- range finder (SIH send_dist_snsr, streams/DISTANCE_SENSOR.hpp) ---------------------------------------------------
DIST_MIN_M, DIST_MAX_M = 0.0, 100.0  # SIH_DISTSNSR_MIN / SIH_DISTSNSR_MAX
DIST_OUT_OF_RANGE_M: Final = 655.35  # beyond its maximum SIH reports UINT16_MAX / 100, as a LightWare LW20 does
MAV_DISTANCE_SENSOR_LASER: Final = 0
MAV_SENSOR_ROTATION_PITCH_270: Final = 25  # facing down


def range_m(snap: VehicleSnapshot) -> float:
    """SIH's downward range finder: height over the ground (local origin) along the body z axis."""
    _, x, y, _ = snap.q_wxyz
    cos_tilt = 1.0 - 2.0 * (x * x + y * y)  # R(2, 2): the body z axis's vertical component
    height = -snap.pos_ned_m[2]
    distance = height / cos_tilt if cos_tilt > 1e-6 else math.inf
    if not isfinite(distance) or distance > DIST_MAX_M:
        return DIST_OUT_OF_RANGE_M
    return max(distance, 0.0)


def distance_sensor(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    """streams/DISTANCE_SENSOR.hpp: metres to centimetres (truncated), instance 0, no variance."""
    return ctx.encoder.distance_sensor_encode(time_boot_ms(snap.time_us), int(DIST_MIN_M * 100),
                                              int(DIST_MAX_M * 100), int(range_m(snap) * 100.0),
                                              MAV_DISTANCE_SENSOR_LASER, 0, MAV_SENSOR_ROTATION_PITCH_270, 0)


# --- vibration (VehicleIMU vibration metrics of SIH's noisy IMU, streams/VIBRATION.hpp) -------------------------------
IMU_DT_S: Final = 0.004  # one 250 Hz sample per integration
# SIH's IMU noise (sih.cpp reconstruct_sensors_signals), std per axis: higher once the motors produce thrust
ACCEL_NOISE = ((0.1, 0.1, 0.1), (0.5, 1.7, 1.4))  # m/s^2: (motors off, motors on)
GYRO_NOISE = ((0.01, 0.01, 0.01), (0.14, 0.07, 0.03))  # rad/s


def _diff_metric(sigma: Vec3) -> float:
    """Expected length of (sample - previous sample) of one integrated noise vector: sqrt(2) dt |sigma|."""
    return math.sqrt(2.0) * IMU_DT_S * math.sqrt(sum(s * s for s in sigma))


def _coning_metric(sigma: Vec3) -> float:
    """Expected length of (delta angle x previous delta angle) for independent noise samples."""
    a, b, c = (s * IMU_DT_S for s in sigma)
    return math.sqrt(2.0 * (a * a * b * b + b * b * c * c + a * a * c * c))


VIBRATION_METRICS = tuple((_coning_metric(g), _diff_metric(g), _diff_metric(a))
                          for a, g in zip(ACCEL_NOISE, GYRO_NOISE, strict=True))


def vibration(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    """vibration_x: gyro coning, vibration_y: gyro high-frequency, vibration_z: accel high-frequency metric (PX4's
    own use of the fields), as SIH's noise makes them settle; no accelerometer clipping."""
    spinning = any(u > 1e-6 for u in snap.motors)
    x, y, z = VIBRATION_METRICS[1 if spinning else 0]
    return ctx.encoder.vibration_encode(snap.time_us, x, y, z, 0, 0, 0)


# --- GNSS (sensor_gps_sim: SIH's GPS) ---------------------------------------------------------------------------------
GPS_DEVICE_ID: Final = 0xAF0004  # DRV_GPS_DEVTYPE_SIM on the simulation bus (device_id: devtype << 16 | bus type 4)
GPS_EPH_M, GPS_EPV_M, GPS_SPEED_VARIANCE_M_S = 0.5, 0.8, 0.2  # what GPS_RAW_INT reports (messages.gps_raw_int)


def gnss_integrity(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    """streams/GNSS_INTEGRITY.hpp: the simulated receiver reports no errors, no authentication, jamming or spoofing
    state and no RAIM (horizontal/vertical figures of merit UINT16_MAX). The id field is a uint8: PX4 assigns the
    32-bit device id to it, which keeps its low byte."""
    return ctx.encoder.gnss_integrity_encode(GPS_DEVICE_ID & 0xFF, 0, 0, 0, 0, 0, 0xFFFF, 0xFFFF, 0, 0, 0, 0)


# MAV_ODID_* (common.xml)
ODID_STATUS_GROUND, ODID_STATUS_AIRBORNE, ODID_STATUS_EMERGENCY = 1, 2, 3
ODID_HOR_ACC_1_METER, ODID_VER_ACC_1_METER, ODID_SPEED_ACC_0_3 = 12, 6, 4
ODID_TIME_ACC_1_0_SECOND: Final = 10
_ODID_ID_OR_MAC = [0] * 20
ODID_EPOCH_2019_S: Final = 1_546_300_800  # OPEN_DRONE_ID_SYSTEM timestamps count from 2019-01-01


def _utc_us(ctx: EndpointContext, snap: VehicleSnapshot) -> int:
    return ctx.node.epoch_unix_us + snap.time_us


def open_drone_id_location(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage:
    """streams/OPEN_DRONE_ID_LOCATION.hpp from the GPS fix, the barometer, the land detector and home."""
    vn, ve, vd = snap.vel_ned_m_s
    status = ODID_STATUS_GROUND if snap.landed_state == 1 else ODID_STATUS_AIRBORNE
    if snap.armed and snap.failsafe:
        status = ODID_STATUS_EMERGENCY
    course = atan2(ve, vn) if isfinite(vn) and isfinite(ve) else 0.0
    direction = clamp_int(100 * iround(degrees(course % (2.0 * math.pi))), 0, 35999)
    speed_h = clamp_int(itrunc(hypot(vn, ve) * 100.0), 0, 25425)
    speed_v = clamp_int(iround(-vd * 100.0), -6200, 6200)
    height = snap.alt_amsl_m - snap.home.alt_amsl_m if snap.home is not None else -1000.0
    utc_ms = _utc_us(ctx, snap) // 1000
    return ctx.encoder.open_drone_id_location_encode(
        0, 0, _ODID_ID_OR_MAC, status, direction, speed_h, speed_v, e7(snap.lat_deg), e7(snap.lon_deg),
        snap.alt_amsl_m, float(iround(snap.alt_amsl_m)), 0, height, ODID_HOR_ACC_1_METER,
        ODID_VER_ACC_1_METER, 0, ODID_SPEED_ACC_0_3, (utc_ms % 3_600_000) / 1000.0, ODID_TIME_ACC_1_0_SECOND)


def open_drone_id_system(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage | None:
    """streams/OPEN_DRONE_ID_SYSTEM.hpp: the operator at the take-off location (home), only once home is valid."""
    home = snap.home
    if home is None:
        return None
    utc_s = _utc_us(ctx, snap) // 1_000_000
    timestamp = utc_s - ODID_EPOCH_2019_S if utc_s >= ODID_EPOCH_2019_S else 0
    return ctx.encoder.open_drone_id_system_encode(
        0, 0, _ODID_ID_OR_MAC, 0, 0, itrunc(home.lat_deg * 1e7), itrunc(home.lon_deg * 1e7), 1, 0,
        -1000.0, -1000.0, 0, 0, home.alt_amsl_m, timestamp & 0xFFFFFFFF)
