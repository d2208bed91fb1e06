"""Multicopter attitude and rate controller parameters.

Sources: PX4 src/modules/mc_att_control/mc_att_control_params.yaml and
src/modules/mc_rate_control/mc_rate_control_params.yaml (defaults as of v1.15-v1.17).
"""

from __future__ import annotations

from sitl_emu.params.registry import ParamDef, integer, real

_ATT: list[ParamDef] = [
    real("MC_ROLL_P", 4.0, 0.0, 12.0, "1/s", "Roll attitude P gain (angle error to rate setpoint)."),
    real("MC_PITCH_P", 4.0, 0.0, 12.0, "1/s", "Pitch attitude P gain (angle error to rate setpoint)."),
    real("MC_YAW_P", 2.8, 0.0, 5.0, "1/s", "Yaw attitude P gain (angle error to rate setpoint)."),
    real("MC_YAW_WEIGHT", 0.4, 0.0, 1.0, "", "Yaw weight: how much yaw is prioritised against roll/pitch."),
    real("MC_ROLLRATE_MAX", 220.0, 0.0, 1800.0, "deg/s", "Maximum roll rate setpoint."),
    real("MC_PITCHRATE_MAX", 220.0, 0.0, 1800.0, "deg/s", "Maximum pitch rate setpoint."),
    real("MC_YAWRATE_MAX", 200.0, 0.0, 1800.0, "deg/s", "Maximum yaw rate setpoint."),
]


def _rate_axis(prefix: str, short: str, p: float, i: float, d: float, axis: str) -> list[ParamDef]:
    return [
        real(f"MC_{prefix}RATE_P", p, 0.01, 0.5, "", f"{axis} rate P gain."),
        real(f"MC_{prefix}RATE_I", i, 0.0, 10.0, "", f"{axis} rate I gain."),
        real(f"MC_{prefix}RATE_D", d, 0.0, 0.01, "", f"{axis} rate D gain."),
        real(f"MC_{prefix}RATE_FF", 0.0, 0.0, 1.0, "", f"{axis} rate feed-forward gain."),
        real(f"MC_{prefix}RATE_K", 1.0, 0.01, 5.0, "", f"{axis} rate controller overall gain (scales P, I, D)."),
        real(f"MC_{short}_INT_LIM", 0.3, 0.0, 1.0, "", f"{axis} rate integrator limit (normalised torque)."),
    ]


PARAMS: list[ParamDef] = [
    *_ATT,
    *_rate_axis("ROLL", "RR", 0.15, 0.2, 0.003, "Roll"),
    *_rate_axis("PITCH", "PR", 0.15, 0.2, 0.003, "Pitch"),
    *_rate_axis("YAW", "YR", 0.2, 0.1, 0.0, "Yaw"),
    integer("MC_AIRMODE", 0, 0, 2, "", "Air mode: 0 disabled (the only mode emulated)."),
    real("MC_YAW_TQ_CUTOFF", 2.0, 0.0, 10.0, "Hz", "Low-pass cutoff of the yaw torque setpoint (0 disables)."),
]
