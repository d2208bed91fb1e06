"""Commander parameters (COM_*, NAV_DLL_ACT, NAV_RCL_ACT) with PX4's defaults for a SITL multicopter.

Sources: src/modules/commander/commander_params.yaml, src/modules/navigator/navigator_params.yaml (NAV_*),
ROMFS/px4fmu_common/init.d-posix/rcS (SITL overrides: COM_RC_IN_MODE 1, COM_LOW_BAT_ACT 3).
See ../shared/reference/px4-behaviour.md section 6.11.
"""

from __future__ import annotations

from sitl_emu.params.registry import ParamDef, integer, real

PARAMS: list[ParamDef] = [
    real("COM_OF_LOSS_T", 1.0, 0.0, 60.0, "s"),
    integer("COM_OBL_RC_ACT", 0, 0, 7),
    real("COM_DISARM_LAND", 2.0, -1.0, 20.0, "s"),
    real("COM_DISARM_PRFLT", 10.0, -1.0, 20.0, "s"),
    real("COM_SPOOLUP_TIME", 1.0, 0.0, 30.0, "s"),
    real("COM_FAIL_ACT_T", 5.0, 0.0, 25.0, "s"),
    integer("COM_DL_LOSS_T", 10, 5, 300, "s"),
    real("COM_RC_LOSS_T", 0.5, 0.0, 35.0, "s"),
    integer("NAV_DLL_ACT", 0, 0, 6),
    integer("NAV_RCL_ACT", 2, 1, 6),
    integer("COM_RCL_EXCEPT", 0, 0, 31),
    integer("COM_ARM_WO_GPS", 1, 0, 2),
    integer("COM_ARM_MIS_REQ", 0, 0, 1),  # 1: no arming in any mode without a valid mission (modeCheck.cpp)
    integer("COM_HOME_EN", 1, 0, 1),
    integer("COM_RC_IN_MODE", 1, 0, 8),  # 5-8: RC and MAVLink by priority
    integer("COM_LOW_BAT_ACT", 3, 0, 4),  # 0 warning, 2 Land, 3 Return then Land, 4 Return then Terminate
]
