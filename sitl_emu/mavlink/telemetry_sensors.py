"""Sensor-style telemetry (HIGHRES_IMU, SCALED_PRESSURE) derived from the vehicle's state, noise-free.

PX4 streams these from sensor_combined / vehicle_air_data (streams/HIGHRES_IMU.hpp, SCALED_PRESSURE.hpp); SIH's
sensors are the true state plus noise. We have no separate sensor model, so: accelerometer = specific force in FRD,
gyro = body rates, magnetometer = a fixed Earth field rotated into the body, barometer = ISA pressure at the altitude.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from sitl_emu.mavlink.telemetry_msgs import rotate_ned_to_body
from sitl_emu.types import VehicleSnapshot

if TYPE_CHECKING:
    from sitl_emu.mavlink.context import EndpointContext
    from sitl_emu.mavlink.fastpack import Packed

GRAVITY_M_S2 = 9.80665
# Earth magnetic field near the SIH default home (Zurich), gauss, NED: ~0.48 G, inclination ~63.5°, declination ~2.5°
MAG_NED_GAUSS = (0.214, 0.009, 0.430)
TEMPERATURE_C = 20.0
HIGHRES_FIELDS_ALL = 0x1FFF  # acc, gyro, mag, abs/diff pressure, pressure altitude, temperature


def isa_pressure_hpa(alt_amsl_m: float) -> float:
    """International Standard Atmosphere pressure at an altitude (troposphere)."""
    return 1013.25 * (1.0 - 2.25577e-5 * alt_amsl_m) ** 5.25588 if alt_amsl_m < 11000 else 226.32


def specific_force_frd(snap: VehicleSnapshot) -> tuple[float, float, float]:
    """What an accelerometer reads: (a - g) in the body frame; -9.81 on z at rest."""
    ax, ay, az = snap.acc_ned_m_s2
    return rotate_ned_to_body(snap.q_wxyz, (ax, ay, az - GRAVITY_M_S2))


def highres_imu(ctx: EndpointContext, snap: VehicleSnapshot) -> Packed:
    acc = specific_force_frd(snap)
    mag = rotate_ned_to_body(snap.q_wxyz, MAG_NED_GAUSS)
    pressure = isa_pressure_hpa(snap.alt_amsl_m)
    return ctx.encoder.highres_imu_encode(snap.time_us, *acc, *snap.rates_frd_rad_s, *mag, pressure, 0.0,
                                      snap.alt_amsl_m, TEMPERATURE_C, HIGHRES_FIELDS_ALL, 0)


def scaled_pressure(ctx: EndpointContext, snap: VehicleSnapshot) -> Packed | None:
    pressure = isa_pressure_hpa(snap.alt_amsl_m)
    if not math.isfinite(pressure):
        return None
    return ctx.encoder.scaled_pressure_encode((snap.time_us // 1000) & 0xFFFFFFFF, pressure, 0.0,
                                          round(TEMPERATURE_C * 100), 0)
