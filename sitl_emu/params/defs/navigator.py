"""Navigator (takeoff, hold, RTL, geofence) and multicopter land-detector parameters.

Defaults: src/modules/navigator/{navigator_params.c, mission_params.yaml, rtl_params.yaml, geofence_params.yaml}
with the multicopter overrides of ROMFS/px4fmu_common/init.d/rc.mc_defaults (RTL_RETURN_ALT 30, RTL_DESCEND_ALT 10), and
src/modules/land_detector/land_detector_params_mc.c (LNDMC_*). The land-detector parameters live in this domain
because the registry loads only the domains listed in sitl_emu/params/__init__.py.
"""

from __future__ import annotations

from sitl_emu.params.registry import ParamDef, integer, real

_NAVIGATOR: list[ParamDef] = [
    real("MIS_TAKEOFF_ALT", 2.5, 0.0, 10000.0, "m"),
    real("NAV_ACC_RAD", 10.0, 0.05, 200.0, "m"),
    real("NAV_MC_ALT_RAD", 0.8, 0.05, 200.0, "m"),
    real("RTL_RETURN_ALT", 30.0, 0.0, 10000.0, "m"),
    real("RTL_DESCEND_ALT", 10.0, 0.0, 10000.0, "m"),
    real("RTL_LAND_DELAY", 0.0, -1.0, 300.0, "s"),
    real("RTL_MIN_DIST", 10.0, 0.5, 10000.0, "m"),
    integer("RTL_CONE_ANG", 45, 0, 90, "deg"),
    integer("RTL_TYPE", 0, 0, 5, ""),
    # geofence_params.yaml (navigator/geofence.cpp reads these)
    integer("GF_ACTION", 2, 0, 5, ""),
    integer("GF_SOURCE", 0, 0, 1, ""),
    real("GF_MAX_HOR_DIST", 0.0, 0.0, 10000.0, "m"),
    real("GF_MAX_VER_DIST", 0.0, 0.0, 10000.0, "m"),
    # AUTO.MISSION (navigator/mission.py): a waypoint's heading, the loiter a finished mission leaves (RTL's climb)
    real("MIS_YAW_ERR", 12.0, 0.0, 90.0, "deg"),
    real("MIS_YAW_TMT", -1.0, -1.0, 20.0, "s"),
    real("NAV_LOITER_RAD", 80.0, -10000.0, 10000.0, "m"),
]

# PX4's navigator looks these up only when a mission is uploaded, so PX4 lists them only from then on (catalog.py: not
# in PX4's boot list, hence known but unused until ParamRegistry.mark_used). mission_params.yaml.
_MISSION_CHECKS: list[ParamDef] = [
    real("MIS_DIST_1WP", 10000.0, -1.0, 100000.0, "m",
         "Warn when the first waypoint is farther than this from home (0 or less: never)."),
    integer("MIS_TKO_LAND_REQ", 0, 0, 5, "", "Whether a mission must contain a takeoff and/or a landing "
                                              "(0: no requirement)."),
]

_LAND_DETECTOR: list[ParamDef] = [
    real("LNDMC_Z_VEL_MAX", 0.25, 0.0, 10.0, "m/s"),
    real("LNDMC_XY_VEL_MAX", 1.5, 0.0, 10.0, "m/s"),
    real("LNDMC_ROT_MAX", 20.0, 0.0, 180.0, "deg/s"),
    real("LNDMC_TRIG_TIME", 1.0, 0.1, 10.0, "s", "Total time the landing conditions must hold (three stages)."),
    real("LNDMC_ALT_GND", 2.0, -1.0, 10.0, "m"),
    real("LNDMC_ALT_MAX", -1.0, -1.0, 10000.0, "m", "Maximum altitude for multicopters (-1: no limit)."),
]

PARAMS: list[ParamDef] = _NAVIGATOR + _MISSION_CHECKS + _LAND_DETECTOR
