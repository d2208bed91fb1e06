"""PX4's parameters -> the plain settings of the pure controllers and the physics.

In PX4 the module wrappers read the parameters (MulticopterPositionControl::parameters_update,
MulticopterAttitudeControl::parameters_updated, MulticopterRateControl::parameters_updated,
MulticopterHoverThrustEstimator::updateParams, Sih::parameters_updated) and hand plain values to the pure classes.
Here the vehicle calls these functions at boot and again whenever `ParamRegistry.version` changes; the controllers
and the physics never see the registry.
"""

from __future__ import annotations

import math

from sitl_emu.control.attitude import AttitudeControlSettings
from sitl_emu.control.cascade import CascadeSettings
from sitl_emu.control.hover import HoverThrustSettings
from sitl_emu.control.position import PositionControlSettings
from sitl_emu.control.qmath import constrain
from sitl_emu.control.rate import RateControlSettings
from sitl_emu.params.registry import ParamRegistry
from sitl_emu.physics import SihConfig

_RATE_AXES = ("ROLL", "PITCH", "YAW")


def cascade_settings(reg: ParamRegistry) -> CascadeSettings:
    spoolup_s = reg.get("COM_SPOOLUP_TIME") if "COM_SPOOLUP_TIME" in reg else 1.0
    return CascadeSettings(position_settings(reg), attitude_settings(reg), rate_settings(reg), hover_settings(reg),
                           spoolup_s, reg.get("MPC_TKO_RAMP_T"))


def position_settings(reg: ParamRegistry) -> PositionControlSettings:
    g = reg.get
    xy_p, xy_vp, xy_vi, xy_vd = g("MPC_XY_P"), g("MPC_XY_VEL_P_ACC"), g("MPC_XY_VEL_I_ACC"), g("MPC_XY_VEL_D_ACC")
    tilt_air_deg = min(g("MPC_TILTMAX_AIR"), 89.0)
    return PositionControlSettings(
        pos_p=(xy_p, xy_p, g("MPC_Z_P")), vel_p=(xy_vp, xy_vp, g("MPC_Z_VEL_P_ACC")),
        vel_i=(xy_vi, xy_vi, g("MPC_Z_VEL_I_ACC")), vel_d=(xy_vd, xy_vd, g("MPC_Z_VEL_D_ACC")),
        thr_hover=constrain(g("MPC_THR_HOVER"), g("MPC_THR_MIN"), g("MPC_THR_MAX")),
        thr_min=g("MPC_THR_MIN"), thr_max=g("MPC_THR_MAX"), thr_xy_margin=g("MPC_THR_XY_MARG"),
        vel_max_xy=g("MPC_XY_VEL_MAX"), vel_max_up=g("MPC_Z_VEL_MAX_UP"), vel_max_dn=g("MPC_Z_VEL_MAX_DN"),
        tilt_max_air_rad=math.radians(tilt_air_deg),
        tilt_max_lnd_rad=math.radians(min(g("MPC_TILTMAX_LND"), tilt_air_deg)),
        veld_lp_hz=g("MPC_VELD_LP"), use_hte=bool(g("MPC_USE_HTE")),
    )


def attitude_settings(reg: ParamRegistry) -> AttitudeControlSettings:
    g = reg.get
    return AttitudeControlSettings(
        gain_p=(g("MC_ROLL_P"), g("MC_PITCH_P"), g("MC_YAW_P")), yaw_weight=g("MC_YAW_WEIGHT"),
        rate_max_rad_s=(math.radians(g("MC_ROLLRATE_MAX")), math.radians(g("MC_PITCHRATE_MAX")),
                        math.radians(g("MC_YAWRATE_MAX"))),
    )


def rate_settings(reg: ParamRegistry) -> RateControlSettings:
    """MC_*RATE_K scales P, I and D (mc_rate_control's parameters_updated)."""
    g = reg.get
    k = [g(f"MC_{axis}RATE_K") for axis in _RATE_AXES]

    def gains(kind: str) -> tuple[float, float, float]:
        return (k[0] * g(f"MC_ROLLRATE_{kind}"), k[1] * g(f"MC_PITCHRATE_{kind}"), k[2] * g(f"MC_YAWRATE_{kind}"))

    return RateControlSettings(
        gain_p=gains("P"), gain_i=gains("I"), gain_d=gains("D"),
        gain_ff=(g("MC_ROLLRATE_FF"), g("MC_PITCHRATE_FF"), g("MC_YAWRATE_FF")),
        int_lim=(g("MC_RR_INT_LIM"), g("MC_PR_INT_LIM"), g("MC_YR_INT_LIM")),
        yaw_tq_cutoff_hz=g("MC_YAW_TQ_CUTOFF"),
    )


def hover_settings(reg: ParamRegistry) -> HoverThrustSettings:
    g = reg.get
    return HoverThrustSettings(g("MPC_THR_HOVER"), g("HTE_HT_NOISE"), g("HTE_ACC_GATE"), g("HTE_HT_ERR_INIT"),
                               g("HTE_VZ_THR"), g("HTE_VXY_THR"), g("HTE_THR_RANGE"))


def sih_config(reg: ParamRegistry) -> SihConfig:
    g = reg.get
    return SihConfig(
        mass_kg=g("SIH_MASS"), ixx=g("SIH_IXX"), iyy=g("SIH_IYY"), izz=g("SIH_IZZ"),
        t_max_n=g("SIH_T_MAX"), q_max_nm=g("SIH_Q_MAX"), l_roll_m=g("SIH_L_ROLL"), l_pitch_m=g("SIH_L_PITCH"),
        kdv=g("SIH_KDV"), kdw=g("SIH_KDW"), t_tau_s=g("SIH_T_TAU"),
        wind_n_m_s=g("SIH_WIND_N"), wind_e_m_s=g("SIH_WIND_E"),
    )
