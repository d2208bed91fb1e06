"""The pxh> `mission` command (a sitl_emu addition: PX4's console has no such command; `navigator status` says
little): a summary of the stored plans and of the mission's progress, one log line each, in PX4's console format.

    INFO  [mission] mission: 5 items, current 2, state ACTIVE, last reached 1
    INFO  [mission] > 2 WAYPOINT 47.3976891 8.5457532 5.0 m rel
    INFO  [mission] fence: 0 items, rally: 0 points
"""

from __future__ import annotations

from sitl_emu.console.param import log_line
from sitl_emu.navigator.mission_store import (
    PLAN_FENCE,
    PLAN_MISSION,
    PLAN_RALLY,
    MissionItem,
    MissionStore,
)
from sitl_emu.px4 import RELATIVE_FRAMES, MavCmd, MavFrame, NavState

_STATES = {1: "NO_MISSION", 2: "NOT_STARTED", 3: "ACTIVE", 4: "PAUSED", 5: "COMPLETE"}
_MISSION_MODES = (NavState.AUTO_MISSION, NavState.AUTO_TAKEOFF, NavState.AUTO_LAND)
USAGE = "Usage: mission [status]  (the stored plans and the mission's progress)\n"


def mission_command(store: MissionStore, nav_state: NavState, args: list[str]) -> tuple[int, str]:
    if args and args[0] != "status":
        return 1, USAGE
    count = store.count(PLAN_MISSION)
    state = _STATES[store.mission_state(nav_state in _MISSION_MODES)]
    head = f"mission: {count} items" if count else "mission: none"
    if count:
        head += f", current {store.current_seq}, state {state}"
        if store.seq_reached >= 0:
            head += f", last reached {store.seq_reached}"
    lines = [head]
    lines += [_item_line(it, it.seq == store.current_seq) for it in store.plan(PLAN_MISSION).items]
    lines.append(f"fence: {store.count(PLAN_FENCE)} items, rally: {store.count(PLAN_RALLY)} points")
    return 0, "".join(log_line("INFO", "mission", line) for line in lines)


def _command_name(command: int) -> str:
    """MAV_CMD_NAV_WAYPOINT -> WAYPOINT, MAV_CMD_DO_JUMP -> DO_JUMP; a number the emulator does not know as is."""
    try:
        return MavCmd(command).name.removeprefix("NAV_")
    except ValueError:
        return f"command {command}"


def _item_line(item: MissionItem, current: bool) -> str:
    name = _command_name(item.command)
    mark = ">" if current else " "
    if item.frame == MavFrame.MISSION:  # no position
        return f"{mark} {item.seq} {name} {item.param1:g} {item.param2:g}"
    alt = "rel" if item.frame in RELATIVE_FRAMES else "AMSL"
    return f"{mark} {item.seq} {name} {item.lat_deg:.7f} {item.lon_deg:.7f} {item.z:.1f} m {alt}"
