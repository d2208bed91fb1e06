"""SIH simulator parameters (PX4 src/modules/simulation/simulator_sih/sih_params.yaml).

SIH_LOC_LAT0 / LON0 / H0 default to PX4's starting point, geo.SIH_HOME (47.397742, 8.545594, 489.4 m AMSL), which is
also the emulator's default home.
"""

from __future__ import annotations

from sitl_emu.geo import SIH_HOME
from sitl_emu.params.registry import ParamDef, integer, real

PARAMS: list[ParamDef] = [
    real("SIH_MASS", 1.0, 0.0, 100.0, "kg"),
    real("SIH_IXX", 0.025, 0.0, 100.0, "kg m^2"),
    real("SIH_IYY", 0.025, 0.0, 100.0, "kg m^2"),
    real("SIH_IZZ", 0.030, 0.0, 100.0, "kg m^2"),
    real("SIH_IXY", 0.0, -100.0, 100.0, "kg m^2"),  # the cross terms are not simulated, only kept for PX4 parity
    real("SIH_IXZ", 0.0, -100.0, 100.0, "kg m^2"),
    real("SIH_IYZ", 0.0, -100.0, 100.0, "kg m^2"),
    real("SIH_T_MAX", 5.0, 0.0, 1000.0, "N"),
    real("SIH_Q_MAX", 0.1, 0.0, 10.0, "Nm"),
    real("SIH_L_ROLL", 0.2, 0.0, 10.0, "m"),
    real("SIH_L_PITCH", 0.2, 0.0, 10.0, "m"),
    real("SIH_KDV", 1.0, 0.0, 10.0, "N/(m/s)"),
    real("SIH_KDW", 0.025, 0.0, 10.0, "Nm/(rad/s)"),
    real("SIH_T_TAU", 0.05, 0.0, 10.0, "s"),
    real("SIH_WIND_N", 0.0, -100.0, 100.0, "m/s"),
    real("SIH_WIND_E", 0.0, -100.0, 100.0, "m/s"),
    real("SIH_LOC_LAT0", SIH_HOME[0], -90.0, 90.0, "deg"),
    real("SIH_LOC_LON0", SIH_HOME[1], -180.0, 180.0, "deg"),
    real("SIH_LOC_H0", SIH_HOME[2], -420.0, 8848.0, "m"),
    real("SIH_LOC_YAW0", 0.0, -3.14159, 3.14159, "rad"),
    integer("SIH_VEHICLE_TYPE", 0, 0, 0),  # 0 multicopter: the only type emulated
]
