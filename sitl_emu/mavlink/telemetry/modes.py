"""AVAILABLE_MODES (#435), sent on request only, as PX4's streams/AVAILABLE_MODES.hpp does.

REQUEST_MESSAGE(435, param2=0) sends one message per mode (mode_index 1..number_modes); param2=i sends mode i;
an index past the end is DENIED. Standard modes (src/lib/modes/standard_modes.hpp) carry no name; the others carry
the ui.hpp name. ADVANCED is set for every mode but Altitude and Position (mode_util::isAdvanced).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from sitl_emu import px4
from sitl_emu.px4 import NavState

if TYPE_CHECKING:

    from sitl_emu.mavlink.context import LinkContext
    from sitl_emu.mavlink.wire.fastpack import Packed

# Multicopter modes of PX4 v1.15 in nav_state order (mode_util::getValidNavStates() of that era).
VALID_MODES: tuple[NavState, ...] = (
    NavState.MANUAL, NavState.ALTCTL, NavState.POSCTL, NavState.AUTO_MISSION, NavState.AUTO_LOITER,
    NavState.AUTO_RTL, NavState.ACRO, NavState.DESCEND, NavState.TERMINATION, NavState.OFFBOARD, NavState.STAB,
    NavState.AUTO_TAKEOFF, NavState.AUTO_LAND, NavState.AUTO_FOLLOW_TARGET, NavState.AUTO_PRECLAND, NavState.ORBIT,
)
# MAV_STANDARD_MODE of the modes that have one (src/lib/modes/standard_modes.hpp); the others are NON_STANDARD (0).
STANDARD_MODE = {NavState.POSCTL: 1, NavState.ORBIT: 2, NavState.ALTCTL: 4, NavState.AUTO_RTL: 5,
                 NavState.AUTO_MISSION: 6, NavState.AUTO_LAND: 7, NavState.AUTO_TAKEOFF: 8}
NOT_USER_SELECTABLE = frozenset({NavState.DESCEND, NavState.TERMINATION})  # failsafe-only states
MODE_PROPERTY_ADVANCED = 1
MODE_PROPERTY_NOT_USER_SELECTABLE = 2


def available_modes(ctx: LinkContext, index_param: float) -> list[Packed] | None:
    """The AVAILABLE_MODES messages for REQUEST_MESSAGE param2; None (DENIED) for an index past the end."""
    index = round(index_param) if math.isfinite(index_param) else 0
    total = len(VALID_MODES)
    if index == 0:
        return [_mode_message(ctx, i, nav) for i, nav in enumerate(VALID_MODES, 1)]
    if 0 < index <= total:
        return [_mode_message(ctx, index, VALID_MODES[index - 1])]
    return None


def _mode_message(ctx: LinkContext, index: int, nav: NavState) -> Packed:
    standard = STANDARD_MODE.get(nav, 0)
    properties = 0 if nav in (NavState.ALTCTL, NavState.POSCTL) else MODE_PROPERTY_ADVANCED
    if nav in NOT_USER_SELECTABLE:
        properties |= MODE_PROPERTY_NOT_USER_SELECTABLE
    name = b"" if standard else px4.UI_NAMES[nav].encode()
    return ctx.encoder.available_modes_encode(len(VALID_MODES), index, standard, px4.custom_mode(nav), properties, name)
