"""Parameters of failure injection, the failure detector, link loss and the estimator's dead reckoning.

Sources: src/modules/failure_injection_manager/failure_injection_manager_params.yaml (SYS_FAILURE_EN; PX4 SITL's
ROMFS/px4fmu_common/init.d-posix/rcS sets it to 1), src/modules/commander/commander_params.yaml (COM_DLL_EXCEPT),
src/lib/circuit_breaker/circuit_breaker_params.yaml (CBRK_FLIGHTTERM), src/modules/commander/failure_detector/
failure_detector_params.yaml (FD_FAIL_*), src/modules/ekf2/params_*.yaml (EKF2_NOAID_TOUT).
The battery parameters (SIM_BAT_*, BAT_*) are in system.py, COM_LOW_BAT_ACT and NAV_DLL_ACT in commander.py.
"""

from __future__ import annotations

from sitl_emu.params.registry import ParamDef, integer, real

PARAMS: list[ParamDef] = [
    integer("SYS_FAILURE_EN", 1, 0, 1),
    integer("COM_DLL_EXCEPT", 0, 0, 31),
    integer("CBRK_FLIGHTTERM", 121212, 0, 121212),
    integer("FD_FAIL_R", 60, 0, 180, "deg"),
    integer("FD_FAIL_P", 60, 0, 180, "deg"),
    real("FD_FAIL_R_TTRI", 0.3, 0.02, 5.0, "s"),
    real("FD_FAIL_P_TTRI", 0.3, 0.02, 5.0, "s"),
    integer("EKF2_NOAID_TOUT", 5000000, 500000, 10000000, "us"),
]
