"""Commander parameters (COM_*, NAV_DLL_ACT, NAV_RCL_ACT) with PX4's defaults for a SITL multicopter.

Sources: src/modules/commander/commander_params.yaml, src/modules/navigator/navigator_params.yaml (NAV_*),
ROMFS/px4fmu_common/init.d-posix/rcS (SITL overrides: COM_RC_IN_MODE 1, COM_LOW_BAT_ACT 3).
See ../shared/reference/px4-behaviour.md section 6.11.
"""

from __future__ import annotations

from sitl_emu.params.registry import ParamDef, integer, real

PARAMS: list[ParamDef] = [
    real("COM_OF_LOSS_T", 1.0, 0.0, 60.0, "s", "Offboard signal lost if no setpoint for this long"),
    integer("COM_OBL_RC_ACT", 0, 0, 7, "", "Offboard loss action: 0 Position, 1 Altitude, 2 Manual, 3 Return, "
                                             "4 Land, 5 Hold, 6 Terminate, 7 Disarm"),
    real("COM_DISARM_LAND", 2.0, -1.0, 20.0, "s", "Disarm this long after landing (<=0 disables)"),
    real("COM_DISARM_PRFLT", 10.0, -1.0, 20.0, "s", "Disarm this long after arming without takeoff (<=0 disables)"),
    real("COM_SPOOLUP_TIME", 1.0, 0.0, 5.0, "s", "Motor spool-up time after arming"),
    real("COM_FAIL_ACT_T", 5.0, 0.0, 25.0, "s", "Hold this long before a generic failsafe action"),
    integer("COM_DL_LOSS_T", 10, 5, 300, "s", "GCS data link loss timeout"),
    real("COM_RC_LOSS_T", 0.5, 0.0, 35.0, "s", "Manual control loss timeout"),
    integer("NAV_DLL_ACT", 0, 0, 6, "", "Data link loss action: 0 Disabled, 1 Hold, 2 Return, 3 Land, "
                                         "5 Terminate, 6 Disarm"),
    integer("NAV_RCL_ACT", 2, 1, 6, "", "Manual control loss action: 1 Hold, 2 Return, 3 Land, 5 Terminate, "
                                         "6 Disarm"),
    integer("COM_RCL_EXCEPT", 0, 0, 31, "", "Modes in which manual control loss is ignored (bitmask)"),
    integer("COM_ARM_WO_GPS", 1, 0, 2, "", "Allow arming without GPS"),
    integer("COM_HOME_EN", 1, 0, 1, "", "Set the home position automatically (at arming)"),
    integer("COM_RC_IN_MODE", 1, 0, 4, "", "Manual control input source (SITL: 1 = MAVLink joystick only)"),
    integer("COM_LOW_BAT_ACT", 3, 0, 3, "", "Low battery action (SITL rcS sets 3)"),
]
