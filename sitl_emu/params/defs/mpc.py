"""Multicopter position controller parameters (PX4 src/modules/mc_pos_control/*_params.yaml, v1.15-v1.17)."""

from __future__ import annotations

from px4common import manual_defaults as manual
from sitl_emu.params.registry import ParamDef, integer, real

_LIMITS: list[ParamDef] = [
    real("MPC_XY_VEL_MAX", 12.0, 0.0, 20.0, "m/s"),
    real("MPC_Z_VEL_MAX_UP", manual.MPC_Z_VEL_MAX_UP, 0.5, 8.0, "m/s"),
    real("MPC_Z_VEL_MAX_DN", manual.MPC_Z_VEL_MAX_DN, 0.5, 4.0, "m/s"),
    real("MPC_TILTMAX_AIR", 45.0, 20.0, 89.0, "deg"),
    real("MPC_TILTMAX_LND", 12.0, 5.0, 89.0, "deg"),
    real("MPC_THR_MIN", 0.12, 0.05, 0.5, "norm"),
    real("MPC_THR_MAX", 1.0, 0.0, 1.0, "norm"),
]

_AUTO: list[ParamDef] = [
    real("MPC_XY_CRUISE", 5.0, 3.0, 20.0, "m/s"),
    real("MPC_Z_V_AUTO_UP", 3.0, 0.5, 8.0, "m/s"),
    real("MPC_Z_V_AUTO_DN", 1.5, 0.5, 4.0, "m/s"),
    real("MPC_ACC_HOR", manual.MPC_ACC_HOR, 2.0, 15.0, "m/s^2"),
    real("MPC_JERK_AUTO", 4.0, 1.0, 80.0, "m/s^3"),
    real("MPC_YAWRAUTO_MAX", 60.0, 5.0, 360.0, "deg/s"),
    real("MPC_YAWRAUTO_ACC", 20.0, 5.0, 360.0, "deg/s^2"),
    real("MPC_XY_ERR_MAX", 2.0, 0.0, 10.0),
    real("MPC_XY_TRAJ_P", 0.5, 0.1, 1.0),
    integer("MPC_YAW_MODE", 0, 0, 5),
]

_MANUAL: list[ParamDef] = [
    real("MPC_ACC_HOR_MAX", 5.0, 2.0, 15.0, "m/s^2"),
    real("MPC_JERK_MAX", manual.MPC_JERK_MAX, 0.5, 500.0, "m/s^3"),
    real("MPC_VEL_MANUAL", manual.MPC_VEL_MANUAL, 3.0, 20.0, "m/s"),
    integer("MPC_POS_MODE", 4, 0, 4),
    real("MPC_ACC_UP_MAX", 4.0, 2.0, 15.0, "m/s^2"),
    real("MPC_ACC_DOWN_MAX", 3.0, 2.0, 15.0, "m/s^2"),
    real("MPC_HOLD_MAX_XY", 0.8, 0.0, 3.0, "m/s"),
    real("MPC_HOLD_MAX_Z", 0.6, 0.0, 3.0, "m/s"),
    integer("MPC_ALT_MODE", 2, 0, 2),
]

_CONTROL: list[ParamDef] = [
    real("MPC_THR_HOVER", 0.5, 0.1, 0.8, "norm"),
    integer("MPC_USE_HTE", 1, 0, 1, "", "Use the hover thrust estimate for altitude control."),
    real("MPC_THR_XY_MARG", 0.3, 0.0, 0.5, "norm"),
    real("MPC_XY_P", 0.95, 0.0, 2.0, "1/s"),
    real("MPC_Z_P", 1.0, 0.1, 1.5, "1/s"),
    real("MPC_XY_VEL_P_ACC", 1.8, 1.2, 5.0, "1/s"),
    real("MPC_XY_VEL_I_ACC", 0.4, 0.0, 60.0, "1/s^2"),
    real("MPC_XY_VEL_D_ACC", 0.2, 0.1, 2.0),
    real("MPC_Z_VEL_P_ACC", 4.0, 2.0, 15.0, "1/s"),
    real("MPC_Z_VEL_I_ACC", 2.0, 0.2, 3.0, "1/s^2"),
    real("MPC_Z_VEL_D_ACC", 0.0, 0.0, 2.0),
    real("MPC_VELD_LP", 5.0, 0.0, 50.0, "Hz"),
]

_TAKEOFF_LAND: list[ParamDef] = [
    real("MPC_TKO_SPEED", 1.5, 1.0, 5.0, "m/s"),
    real("MPC_TKO_RAMP_T", 3.0, 0.0, 5.0, "s"),
    real("MPC_LAND_SPEED", 0.7, 0.6, 4.0, "m/s"),
    real("MPC_LAND_CRWL", 0.3, 0.1, 10.0, "m/s"),
    real("MPC_LAND_ALT1", 10.0, 0.0, 122.0, "m"),
    real("MPC_LAND_ALT2", 5.0, 0.0, 122.0, "m"),
    real("MPC_LAND_ALT3", 1.0, 0.0, 122.0, "m"),
]

# Hover thrust estimator (src/modules/mc_hover_thrust_estimator/hover_thrust_estimator_params.yaml); it feeds
# MPC_THR_HOVER's online refinement, so it lives with the position controller's parameters.
_HTE: list[ParamDef] = [
    real("HTE_HT_NOISE", 0.0036, 0.0001, 1.0, "normalized_thrust/s"),
    real("HTE_ACC_GATE", 3.0, 1.0, 10.0, "SD"),
    real("HTE_HT_ERR_INIT", 0.1, 0.0, 1.0, "normalized_thrust"),
    real("HTE_VXY_THR", 10.0, 1.0, 20.0, "m/s"),
    real("HTE_VZ_THR", 2.0, 1.0, 10.0, "m/s"),
    real("HTE_THR_RANGE", 0.2, 0.01, 0.4, "normalized_thrust"),
]

# The flight tasks Orbit and Follow Target (src/modules/flight_mode_manager/tasks/Orbit/flight_task_orbit_params.yaml,
# tasks/AutoFollowTarget/follow_target_params.yaml); they run in flight_mode_manager, beside the position controller.
_FLIGHT_TASKS: list[ParamDef] = [
    real("MC_ORBIT_RAD_MAX", 1000.0, 1.0, 10000.0, "m"),
    integer("MC_ORBIT_YAW_MOD", 0, 0, 4),
    real("FLW_TGT_RS", 0.1, 0.0, 1.0),
    real("FLW_TGT_HT", 8.0, 8.0, unit="m"),
    real("FLW_TGT_DST", 8.0, 1.0, unit="m"),
    real("FLW_TGT_FA", 180.0, -180.0, 180.0),
    integer("FLW_TGT_ALT_M", 0, 0, 2),
    real("FLW_TGT_MAX_VEL", 5.0, 0.0, 20.0),
]

PARAMS: list[ParamDef] = [*_LIMITS, *_AUTO, *_MANUAL, *_CONTROL, *_TAKEOFF_LAND, *_HTE, *_FLIGHT_TASKS]
