"""PX4 system parameters that ground stations and APIs expect to find (px4-behaviour.md 9c.3).

Defaults are PX4's SITL values: the yaml defaults (src/modules/mavlink/mavlink_params.yaml,
src/modules/commander/commander_params.yaml, src/lib/battery/module.yaml, src/modules/sensors/*.yaml,
src/modules/simulation/battery_simulator/battery_simulator_params.yaml) as overridden by the SITL start-up
scripts (ROMFS/px4fmu_common/init.d-posix/rcS: simulated sensor calibration ids, BAT1_N_CELLS 4,
MAV_PROTO_VER 2, SENS_BOARD_X_OFF 0.000001, SENS_DPRES_OFF 0.001; airframe 10040_sihsim_quadx: SYS_AUTOSTART 10040;
rc.mc_defaults: MAV_TYPE 2). Most of them only exist so clients find them; MAV_SYS_ID, MAV_HASH_CHK_EN and
MAV_FWDEXTSP are read by the link layer.
"""

from __future__ import annotations

from sitl_emu.params.registry import ParamDef, integer, real

# Simulated IMU/magnetometer device ids as PX4 SITL sets them (rcS: "DRV_IMU_DEVTYPE_SIM, BUS: 1, ADDR: 1").
_SIM_IMU0_ID = 1310988
_SIM_MAG0_ID = 197388
_SIM_MAG1_ID = 197644

_MAVLINK = [
    integer("MAV_SYS_ID", 1, 1, 250),
    integer("MAV_COMP_ID", 1, 1, 250),
    integer("MAV_TYPE", 2, 0, 23),
    integer("MAV_PROTO_VER", 2, 0, 2),  # SITL sets 2
    integer("MAV_HASH_CHK_EN", 1, 0, 1),
    integer("MAV_FWDEXTSP", 1, 0, 1),
    integer("MAV_USEHILGPS", 0, 0, 1),
]

_SYSTEM = [
    integer("SYS_AUTOSTART", 10040, 0, 9999999),
    integer("SYS_AUTOCONFIG", 0, 0, 2),
    integer("SYS_PARAM_VER", 1, 0, 2**31 - 1),
    integer("SYS_HITL", 0, -1, 2),
    integer("SYS_MC_EST_GROUP", 2, 1, 3, doc="Estimator group (2 = EKF2)"),
    integer("SYS_HAS_MAG", 1, 0, 2),
    integer("SYS_HAS_BARO", 1, 0, 1),
    # logger_params.yaml: -1 off, 0 armed to disarmed, 1 boot to first disarm (SITL's), 2 boot to shutdown, 3 RC
    # AUX1, 4 first arming to shutdown (the enum's values as bounds: PX4 states none); read once at start (log/)
    integer("SDLOG_MODE", 1, -1, 4),
]

_BATTERY = [
    real("BAT_CRIT_THR", 0.07, 0.05, 0.5, "norm"),
    real("BAT_EMERGEN_THR", 0.05, 0.03, 0.5, "norm"),
    real("BAT_LOW_THR", 0.15, 0.12, 0.5, "norm"),
    integer("BAT1_N_CELLS", 4, 0, 50),
    real("BAT1_V_CHARGED", 4.05, 0.0, 10.0, "V"),
    real("BAT1_V_EMPTY", 3.6, 0.0, 10.0, "V"),
    real("BAT1_CAPACITY", -1.0, -1.0, 100000.0, "mAh"),
    real("SIM_BAT_DRAIN", 60.0, 0.0, 86400.0, "s"),
    real("SIM_BAT_MIN_PCT", 50.0, 0.0, 100.0, "%"),
    integer("SIM_BAT_ENABLE", 1, 0, 1, doc="Simulate a battery"),
]

_CALIBRATION = [
    integer("CAL_ACC0_ID", _SIM_IMU0_ID),
    integer("CAL_GYRO0_ID", _SIM_IMU0_ID),
    integer("CAL_MAG0_ID", _SIM_MAG0_ID),
    integer("CAL_MAG0_ROT", -1, -1, 100),
    integer("CAL_MAG1_ID", _SIM_MAG1_ID),
    integer("CAL_MAG1_ROT", -1, -1, 100),
    integer("CAL_MAG2_ID", 0),
    integer("CAL_MAG2_ROT", -1, -1, 100),
    integer("CAL_MAG3_ID", 0),
    integer("CAL_MAG3_ROT", -1, -1, 100),
]

_SENSORS = [
    integer("SENS_BOARD_ROT", 0, -1, 40),
    real("SENS_BOARD_X_OFF", 0.000001, -45.0, 45.0, "deg"),
    real("SENS_BOARD_Y_OFF", 0.0, -45.0, 45.0, "deg"),
    real("SENS_BOARD_Z_OFF", 0.0, -45.0, 45.0, "deg"),
    real("SENS_DPRES_OFF", 0.001),
    integer("SENS_EN_GPSSIM", 1, 0, 1),
    integer("SENS_EN_BAROSIM", 1, 0, 1),
    integer("SENS_EN_MAGSIM", 1, 0, 1),
    integer("TRIG_MODE", 0, 0, 4),
    integer("UAVCAN_ENABLE", 0, 0, 3, doc="UAVCAN mode (0 = disabled)"),
]

PARAMS: list[ParamDef] = [*_MAVLINK, *_SYSTEM, *_BATTERY, *_CALIBRATION, *_SENSORS]
