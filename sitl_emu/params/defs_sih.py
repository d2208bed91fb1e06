"""SIH simulator parameters (PX4 src/modules/simulation/simulator_sih/sih_params.yaml).

Deviation: SIH_LOC_H0 defaults to 488.0 m (the Gazebo/jMAVSim world elevation) instead of SIH's 489.4 m, so the
project's home is 47.397742, 8.545594, 488.0 m AMSL.
"""

from __future__ import annotations

from sitl_emu.params.registry import ParamDef, integer, real

PARAMS: list[ParamDef] = [
    real("SIH_MASS", 1.0, 0.0, 100.0, "kg", "Vehicle mass."),
    real("SIH_IXX", 0.025, 0.0, 100.0, "kg m^2", "Vehicle inertia about the body X axis."),
    real("SIH_IYY", 0.025, 0.0, 100.0, "kg m^2", "Vehicle inertia about the body Y axis."),
    real("SIH_IZZ", 0.030, 0.0, 100.0, "kg m^2", "Vehicle inertia about the body Z axis."),
    real("SIH_IXY", 0.0, -100.0, 100.0, "kg m^2", "Vehicle cross inertia XY (not simulated, kept for PX4 parity)."),
    real("SIH_IXZ", 0.0, -100.0, 100.0, "kg m^2", "Vehicle cross inertia XZ (not simulated, kept for PX4 parity)."),
    real("SIH_IYZ", 0.0, -100.0, 100.0, "kg m^2", "Vehicle cross inertia YZ (not simulated, kept for PX4 parity)."),
    real("SIH_T_MAX", 5.0, 0.0, 1000.0, "N", "Maximum thrust of one rotor at full command."),
    real("SIH_Q_MAX", 0.1, 0.0, 10.0, "N m", "Maximum reaction torque of one rotor at full command."),
    real("SIH_L_ROLL", 0.2, 0.0, 10.0, "m", "Roll arm length (rotor offset along body Y)."),
    real("SIH_L_PITCH", 0.2, 0.0, 10.0, "m", "Pitch arm length (rotor offset along body X)."),
    real("SIH_KDV", 1.0, 0.0, 10.0, "N/(m/s)", "First-order drag coefficient on air-relative velocity."),
    real("SIH_KDW", 0.025, 0.0, 10.0, "N m/(rad/s)", "First-order angular damping coefficient."),
    real("SIH_T_TAU", 0.05, 0.0, 10.0, "s", "Motor time constant (first-order lag)."),
    real("SIH_WIND_N", 0.0, -100.0, 100.0, "m/s", "Constant wind velocity, north component."),
    real("SIH_WIND_E", 0.0, -100.0, 100.0, "m/s", "Constant wind velocity, east component."),
    real("SIH_LOC_LAT0", 47.397742, -90.0, 90.0, "deg", "Initial geodetic latitude (local origin)."),
    real("SIH_LOC_LON0", 8.545594, -180.0, 180.0, "deg", "Initial geodetic longitude (local origin)."),
    real("SIH_LOC_H0", 488.0, -420.0, 8848.0, "m", "Initial AMSL ground altitude (local origin)."),
    real("SIH_LOC_YAW0", 0.0, -180.0, 180.0, "deg", "Initial heading."),
    integer("SIH_VEHICLE_TYPE", 0, 0, 0, "", "Vehicle type: 0 multicopter (the only one emulated)."),
]
