"""PX4's defaults of the parameters that shape the manual modes' answer to the sticks (Position, Altitude).

sitl_emu flies with them (its parameter definitions take these defaults; a user may set others) and joyfly models
PX4 with them (joyfly/sticks/manual_fence.py: how fast a stick moves the vehicle, so the fence can stop it in time;
joyfly cannot read a real vehicle's values). PX4 main, 2026: src/modules/mc_pos_control/multicopter_*_params.yaml,
src/lib/sticks/Sticks.cpp; tests/px4common/test_manual_defaults.py checks them against PX4's parameter list.
"""

from __future__ import annotations

from typing import Final

MPC_VEL_MANUAL: Final = 10.0  # m/s, the horizontal speed at full stick in Position mode
MPC_ACC_HOR: Final = 3.0  # m/s^2
MPC_JERK_MAX: Final = 8.0  # m/s^3
MPC_MAN_TILT_MAX: Final = 35.0  # deg, the tilt at full stick in Altitude mode
MPC_Z_VEL_MAX_UP: Final = 3.0  # m/s, the climb at full throttle
MPC_Z_VEL_MAX_DN: Final = 1.5  # m/s, the descent at zero throttle
MAN_DEADZONE: Final = 0.1  # of the stick's travel
STICK_EXPO: Final = 0.6  # Sticks.cpp's fixed expo (the old default of MPC_XY_MAN_EXPO, MPC_Z_MAN_EXPO, MPC_YAW_EXPO)
