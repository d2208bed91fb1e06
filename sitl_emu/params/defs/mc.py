"""Multicopter attitude and rate controller parameters.

Sources: PX4 src/modules/mc_att_control/mc_att_control_params.yaml and
src/modules/mc_rate_control/mc_rate_control_params.yaml (defaults as of v1.15-v1.17). The descriptions are in
px4_param_meta.csv, as for every parameter PX4 lists.
"""

from __future__ import annotations

from sitl_emu.params.registry import ParamDef, integer, real

_ATT: list[ParamDef] = [
    real("MC_ROLL_P", 4.0, 0.0, 12.0, "1/s"),
    real("MC_PITCH_P", 4.0, 0.0, 12.0, "1/s"),
    real("MC_YAW_P", 2.8, 0.0, 5.0, "1/s"),
    real("MC_YAW_WEIGHT", 0.4, 0.0, 1.0),
    real("MC_ROLLRATE_MAX", 220.0, 0.0, 1800.0, "deg/s"),
    real("MC_PITCHRATE_MAX", 220.0, 0.0, 1800.0, "deg/s"),
    real("MC_YAWRATE_MAX", 200.0, 0.0, 1800.0, "deg/s"),
]


def _rate_axis(prefix: str, short: str, gains: tuple[float, float, float],
               p_range: tuple[float, float]) -> list[ParamDef]:
    """One axis of the rate controller: PX4's P range differs per axis; I, D, FF and the integrator limit have no PX4
    maximum, so ours keep them sane."""
    p, i, d = gains
    return [
        real(f"MC_{prefix}RATE_P", p, *p_range),
        real(f"MC_{prefix}RATE_I", i, 0.0, 10.0),
        real(f"MC_{prefix}RATE_D", d, 0.0, 0.01),
        real(f"MC_{prefix}RATE_FF", 0.0, 0.0, 1.0),
        real(f"MC_{prefix}RATE_K", 1.0, 0.01, 5.0),
        real(f"MC_{short}_INT_LIM", 0.3, 0.0, 1.0),
    ]


PARAMS: list[ParamDef] = [
    *_ATT,
    *_rate_axis("ROLL", "RR", (0.15, 0.2, 0.003), (0.01, 0.5)),
    *_rate_axis("PITCH", "PR", (0.15, 0.2, 0.003), (0.01, 0.6)),
    *_rate_axis("YAW", "YR", (0.2, 0.1, 0.0), (0.0, 0.6)),
    integer("MC_AIRMODE", 0, 0, 2),  # 0: disabled, the only air mode emulated
    real("MC_YAW_TQ_CUTOFF", 2.0, 0.0, 10.0, "Hz"),
]
