"""Multicopter position controller parameters (PX4 src/modules/mc_pos_control/*_params.yaml, v1.15-v1.17)."""

from __future__ import annotations

from sitl_emu.params.registry import ParamDef, integer, real

_LIMITS: list[ParamDef] = [
    real("MPC_XY_VEL_MAX", 12.0, 0.0, 20.0, "m/s", "Maximum horizontal velocity."),
    real("MPC_Z_VEL_MAX_UP", 3.0, 0.5, 8.0, "m/s", "Maximum ascent velocity."),
    real("MPC_Z_VEL_MAX_DN", 1.5, 0.5, 4.0, "m/s", "Maximum descent velocity."),
    real("MPC_TILTMAX_AIR", 45.0, 20.0, 89.0, "deg", "Maximum tilt angle in air."),
    real("MPC_TILTMAX_LND", 12.0, 10.0, 89.0, "deg", "Maximum tilt during takeoff ramp and landing."),
    real("MPC_THR_MIN", 0.12, 0.05, 0.5, "", "Minimum collective thrust in auto/position control."),
    real("MPC_THR_MAX", 1.0, 0.0, 1.0, "", "Maximum collective thrust in auto/position control."),
]

_AUTO: list[ParamDef] = [
    real("MPC_XY_CRUISE", 5.0, 3.0, 20.0, "m/s", "Default horizontal velocity in autonomous modes."),
    real("MPC_Z_V_AUTO_UP", 3.0, 0.5, 8.0, "m/s", "Ascent velocity in autonomous modes."),
    real("MPC_Z_V_AUTO_DN", 1.5, 0.5, 4.0, "m/s", "Descent velocity in autonomous modes."),
    real("MPC_ACC_HOR", 3.0, 2.0, 15.0, "m/s^2", "Horizontal acceleration in autonomous modes."),
    real("MPC_JERK_AUTO", 4.0, 1.0, 80.0, "m/s^3", "Jerk limit in autonomous modes."),
    real("MPC_YAWRAUTO_MAX", 60.0, 0.0, 360.0, "deg/s", "Maximum yaw rate in autonomous modes."),
    real("MPC_YAWRAUTO_ACC", 20.0, 5.0, 360.0, "deg/s^2", "Maximum yaw acceleration in autonomous modes."),
    real("MPC_XY_ERR_MAX", 2.0, 0.1, 10.0, "", "Maximum horizontal error allowed by the trajectory generator."),
    real("MPC_XY_TRAJ_P", 0.5, 0.1, 1.0, "", "Proportional gain of the horizontal trajectory position error."),
    integer("MPC_YAW_MODE", 0, 0, 4, "", "Heading behaviour in autonomous modes (0: towards waypoint)."),
]

_MANUAL: list[ParamDef] = [
    real("MPC_ACC_HOR_MAX", 5.0, 2.0, 15.0, "m/s^2", "Maximum horizontal acceleration in position mode."),
    real("MPC_JERK_MAX", 8.0, 0.5, 500.0, "m/s^3", "Maximum jerk in position mode."),
    real("MPC_VEL_MANUAL", 10.0, 3.0, 20.0, "m/s", "Maximum horizontal velocity in position mode."),
    integer("MPC_POS_MODE", 4, 0, 4, "", "Position mode stick input type (4: acceleration based)."),
    real("MPC_ACC_UP_MAX", 4.0, 2.0, 15.0, "m/s^2", "Maximum upwards acceleration in climb-rate modes."),
    real("MPC_ACC_DOWN_MAX", 3.0, 2.0, 15.0, "m/s^2", "Maximum downwards acceleration in climb-rate modes."),
    real("MPC_HOLD_MAX_XY", 0.8, 0.0, 3.0, "m/s", "Maximum horizontal velocity for which position hold is enabled."),
    real("MPC_HOLD_MAX_Z", 0.6, 0.0, 3.0, "m/s", "Maximum vertical velocity for which altitude hold is enabled."),
    integer("MPC_ALT_MODE", 2, 0, 2, "", "Altitude reference mode (2: terrain hold)."),
]

_CONTROL: list[ParamDef] = [
    real("MPC_THR_HOVER", 0.5, 0.1, 0.8, "", "Vertical thrust required to hover (refined online by the estimator)."),
    integer("MPC_USE_HTE", 1, 0, 1, "", "Use the hover thrust estimate for altitude control."),
    real("MPC_THR_XY_MARG", 0.3, 0.0, 0.5, "", "Horizontal thrust margin kept when vertical thrust saturates."),
    real("MPC_XY_P", 0.95, 0.0, 2.0, "1/s", "Horizontal position P gain."),
    real("MPC_Z_P", 1.0, 0.1, 1.5, "1/s", "Vertical position P gain."),
    real("MPC_XY_VEL_P_ACC", 1.8, 1.2, 5.0, "1/s", "Horizontal velocity P gain (to acceleration)."),
    real("MPC_XY_VEL_I_ACC", 0.4, 0.0, 60.0, "1/s^2", "Horizontal velocity I gain."),
    real("MPC_XY_VEL_D_ACC", 0.2, 0.1, 2.0, "", "Horizontal velocity D gain."),
    real("MPC_Z_VEL_P_ACC", 4.0, 2.0, 15.0, "1/s", "Vertical velocity P gain (to acceleration)."),
    real("MPC_Z_VEL_I_ACC", 2.0, 0.2, 3.0, "1/s^2", "Vertical velocity I gain."),
    real("MPC_Z_VEL_D_ACC", 0.0, 0.0, 2.0, "", "Vertical velocity D gain."),
    real("MPC_VELD_LP", 5.0, 0.0, 10.0, "Hz", "Low-pass cutoff of the velocity derivative used by the D term."),
]

_TAKEOFF_LAND: list[ParamDef] = [
    real("MPC_TKO_SPEED", 1.5, 1.0, 5.0, "m/s", "Takeoff climb rate."),
    real("MPC_TKO_RAMP_T", 3.0, 0.0, 5.0, "s", "Smooth takeoff ramp time constant."),
    real("MPC_LAND_SPEED", 0.7, 0.6, 4.0, "m/s", "Landing descend rate."),
    real("MPC_LAND_CRWL", 0.3, 0.1, 10.0, "m/s", "Land crawl descend rate (below MPC_LAND_ALT3 with a range sensor)."),
    real("MPC_LAND_ALT1", 10.0, 0.0, 122.0, "m", "Altitude for the first step of the slow-down descent."),
    real("MPC_LAND_ALT2", 5.0, 0.0, 122.0, "m", "Altitude for the second step of the slow-down descent."),
    real("MPC_LAND_ALT3", 1.0, 0.0, 122.0, "m", "Altitude below which MPC_LAND_CRWL applies."),
]

# Hover thrust estimator (src/modules/mc_hover_thrust_estimator/hover_thrust_estimator_params.yaml); it feeds
# MPC_THR_HOVER's online refinement, so it lives with the position controller's parameters.
_HTE: list[ParamDef] = [
    real("HTE_HT_NOISE", 0.0036, 0.0001, 1.0, "", "Hover thrust process noise (standard deviation)."),
    real("HTE_ACC_GATE", 3.0, 1.0, 10.0, "SD", "Gate size for the acceleration fusion."),
    real("HTE_HT_ERR_INIT", 0.1, 0.0, 1.0, "", "Initial hover thrust uncertainty (standard deviation)."),
    real("HTE_VXY_THR", 10.0, 1.0, 20.0, "m/s", "Horizontal speed above which measurements are trusted less."),
    real("HTE_VZ_THR", 2.0, 1.0, 10.0, "m/s", "Vertical speed above which measurements are trusted less."),
    real("HTE_THR_RANGE", 0.2, 0.01, 0.4, "", "Maximum deviation of the estimate from MPC_THR_HOVER."),
]

PARAMS: list[ParamDef] = [*_LIMITS, *_AUTO, *_MANUAL, *_CONTROL, *_TAKEOFF_LAND, *_HTE]
