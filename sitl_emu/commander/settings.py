"""The commander's parameters as one value, read again only when a parameter changes (commander_params.yaml names)."""

from __future__ import annotations

from dataclasses import dataclass

from sitl_emu.commander.failsafe import FallbackSettings
from sitl_emu.commander.fault_failsafes import FaultSettings
from sitl_emu.commander.manual_control import INPUT_DISABLED, ManualLossSettings
from sitl_emu.params import ParamRegistry


@dataclass(frozen=True, slots=True)
class CommanderSettings:
    """The commander's parameters, read once per parameter change (commander_params.yaml names)."""

    of_loss_us: int  # COM_OF_LOSS_T
    disarm_land_us: int  # COM_DISARM_LAND (<= 0: off)
    preflight_disarm_us: int  # COM_SPOOLUP_TIME + COM_DISARM_PRFLT (COM_DISARM_PRFLT <= 0: off)
    home_enabled: bool  # COM_HOME_EN
    fallback: FallbackSettings  # COM_OBL_RC_ACT, NAV_RCL_ACT
    rc_loss_us: int  # COM_RC_LOSS_T
    rc_in_mode: int  # COM_RC_IN_MODE
    manual_loss: ManualLossSettings  # NAV_RCL_ACT, COM_RCL_EXCEPT, COM_FAIL_ACT_T
    arm_gesture: bool  # MAN_ARM_GESTURE
    override_speed: float  # MAN_OVERRIDE_SPD (1/s; negative: sticks never take over)
    faults: FaultSettings  # NAV_DLL_ACT, COM_LOW_BAT_ACT, CBRK_FLIGHTTERM... (commander/fault_failsafes.py)
    arm_mission_required: bool = False  # COM_ARM_MIS_REQ

    @classmethod
    def from_params(cls, p: ParamRegistry) -> CommanderSettings:
        prflt_s = float(p["COM_DISARM_PRFLT"])
        return cls(
            of_loss_us=int(float(p["COM_OF_LOSS_T"]) * 1e6),
            disarm_land_us=int(float(p["COM_DISARM_LAND"]) * 1e6),
            preflight_disarm_us=int((float(p["COM_SPOOLUP_TIME"]) + prflt_s) * 1e6) if prflt_s > 0 else 0,
            home_enabled=bool(p["COM_HOME_EN"]),
            fallback=FallbackSettings(obl_rc_act=int(p["COM_OBL_RC_ACT"]), rcl_act=int(p["NAV_RCL_ACT"])),
            rc_loss_us=int(float(p["COM_RC_LOSS_T"]) * 1e6),
            rc_in_mode=int(p["COM_RC_IN_MODE"]),
            manual_loss=ManualLossSettings(rcl_act=int(p["NAV_RCL_ACT"]), rcl_except=int(p["COM_RCL_EXCEPT"]),
                                           fail_act_us=int(float(p["COM_FAIL_ACT_T"]) * 1e6),
                                           input_disabled=int(p["COM_RC_IN_MODE"]) == INPUT_DISABLED),
            arm_gesture=int(p["MAN_ARM_GESTURE"]) == 1,
            override_speed=float(p["MAN_OVERRIDE_SPD"]),
            faults=FaultSettings.from_params(p),
            arm_mission_required=bool(p["COM_ARM_MIS_REQ"]),
        )
