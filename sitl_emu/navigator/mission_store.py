"""The vehicle's stored plans: mission, geofence and rally points (PX4's dataman, owned by the navigator side).

In PX4 the MAVLink mission manager (src/modules/mavlink/mavlink_mission.cpp) writes uploaded items into dataman and
publishes the `mission` topic (count, current_seq, a CRC32 of the plan per type) that the navigator flies. Here the
store is that dataman plus topic, in memory, with no MAVLink: the protocol handler (sitl_emu/mavlink/
protocols/mission.py) turns wire messages into MissionItem values and replaces a whole plan at once, so a plan is
never half-written (PX4 writes a transfer into the inactive dataman slot and switches slots only when it completes).

Not persistent: PX4 SITL keeps dataman in a `dataman` file in its working directory, so there a plan survives a
restart only when the same directory is reused; the emulator has no storage file, so a plan lives until `shutdown`
or a reboot (Vehicle._boot builds a new, empty store), like PX4 started in a fresh working directory.

Also here: the one-transfer-at-a-time lock PX4 keeps across all MAVLink instances (`_transfer_in_progress` is a
static member of MavlinkMissionManager): a second link's MISSION_COUNT is refused while another link uploads.
"""

from __future__ import annotations

import struct
import zlib
from dataclasses import dataclass, field
from typing import Final

PLAN_MISSION: Final = 0
PLAN_FENCE: Final = 1
PLAN_RALLY: Final = 2
PLAN_ALL: Final = 255  # MAV_MISSION_TYPE_ALL: MISSION_CLEAR_ALL of every plan
PLAN_TYPES: Final = (PLAN_MISSION, PLAN_FENCE, PLAN_RALLY)

# How many items each plan holds (MavlinkMissionManager::MAX_COUNT from dataman.h: the mission's
# CONFIG_NUM_MISSION_ITMES_SUPPORTED, 10000 in the px4_sitl board configuration as a third party reports it (Kconfig's
# default is 500; not re-checked against the board file); DM_KEY_FENCE_POINTS_MAX 64, DM_KEY_SAFE_POINTS_MAX 32).
MAX_ITEMS = {PLAN_MISSION: 10_000, PLAN_FENCE: 64, PLAN_RALLY: 32}

# MISSION_STATE (common.xml), what MISSION_CURRENT reports for the stored mission
MISSION_STATE_NO_MISSION: Final = 1
MISSION_STATE_NOT_STARTED: Final = 2
MISSION_STATE_ACTIVE: Final = 3
MISSION_STATE_PAUSED: Final = 4
MISSION_STATE_COMPLETE: Final = 5


@dataclass(frozen=True, slots=True)
class MissionItem:
    """One stored item, in MAVLink's terms (MISSION_ITEM_INT fields; x/y are degE7 for global frames)."""

    seq: int
    frame: int
    command: int
    autocontinue: int
    param1: float
    param2: float
    param3: float
    param4: float
    x: int
    y: int
    z: float

    @property
    def lat_deg(self) -> float:
        return self.x * 1e-7

    @property
    def lon_deg(self) -> float:
        return self.y * 1e-7


@dataclass(frozen=True, slots=True)
class Plan:
    items: tuple[MissionItem, ...] = ()
    opaque_id: int = 0  # CRC32 of the plan (0 when empty), PX4's _crc32[type] / MISSION_COUNT.opaque_id

    @property
    def count(self) -> int:
        return len(self.items)


def plan_id(items: tuple[MissionItem, ...]) -> int:
    """A CRC32 over each item's frame, command, autocontinue and seven params (PX4 crc32_for_mission_item chains
    crc32part over the same fields; the byte layout here is our own, so the value differs from PX4's)."""
    crc = 0
    for it in items:
        crc = zlib.crc32(struct.pack("<BHB4fiif", it.frame, it.command, it.autocontinue, it.param1, it.param2,
                                     it.param3, it.param4, it.x, it.y, it.z), crc)
    return crc


@dataclass(slots=True)
class MissionStore:
    """The three plans, the mission's current item and the vehicle-wide transfer lock."""

    # indexed by plan type (PLAN_TYPES are 0, 1, 2): a list, as the navigator's geofence check reads two plans every
    # commander cycle (a dict look-up hashes a boxed int)
    plans: list[Plan] = field(default_factory=lambda: [Plan() for _ in PLAN_TYPES])
    current_seq: int = 0
    transfer_owner: object | None = None  # the link (protocol handler) whose upload is running
    uploads: int = 0  # completed mission uploads (PX4 looks MIS_DIST_1WP etc. up from the first one)
    # the navigator's mission_result (flight_tasks/mission.py publishes it): the last item reached, the end
    seq_reached: int = -1
    finished: bool = False
    current_changes: int = 0  # MISSION_SET_CURRENT / MISSION_START requests, for the navigator to follow
    jump_resets: int = 0  # DO_SET_MISSION_CURRENT param2 = 1 requests, for the navigator to follow
    fence_violation: str | None = None  # the navigator's mission-vs-geofence check (vehicle/fence.py), None: passes

    def plan(self, plan_type: int) -> Plan:
        return self.plans[plan_type]

    def count(self, plan_type: int) -> int:
        return self.plans[plan_type].count

    def replace(self, plan_type: int, items: tuple[MissionItem, ...], current_seq: int = 0) -> Plan:
        """Store a whole plan (a completed upload); the mission's current item is the one the upload marked, else
        0 (update_active_mission with the transfer's current seq; -1 there means the first item)."""
        plan = Plan(items, plan_id(items) if items else 0)
        self.plans[plan_type] = plan
        if plan_type == PLAN_MISSION:
            self.current_seq = max(current_seq, 0)
            self.seq_reached, self.finished = -1, False
        return plan

    def clear(self, plan_type: int) -> None:
        for t in PLAN_TYPES if plan_type == PLAN_ALL else (plan_type,):
            self.replace(t, ())

    def set_current(self, seq: int) -> bool:
        """MISSION_SET_CURRENT / MISSION_START: only an index inside the stored mission. A mission pointed at an item
        is not complete any more (the navigator's set_current clears mission_result.finished): MISSION_CURRENT says
        so at once, not COMPLETE until the navigator's next cycle."""
        if not 0 <= seq < self.count(PLAN_MISSION):
            return False
        self.current_seq = seq
        self.current_changes += 1
        self.finished = False
        return True

    def reset_jumps(self) -> None:
        """DO_SET_MISSION_CURRENT param2 = 1: every DO_JUMP counts from zero again and the mission is not complete
        (Mission::set_current_mission_index with reset_jump_counters)."""
        self.jump_resets += 1
        self.finished = False

    def try_lock(self, owner: object) -> bool:
        if self.transfer_owner is not None and self.transfer_owner is not owner:
            return False
        self.transfer_owner = owner
        return True

    def unlock(self, owner: object) -> None:
        if self.transfer_owner is owner:
            self.transfer_owner = None

    @property
    def mission_valid(self) -> bool:
        """mission_result.valid: PX4 main's feasibility checks refuse none of the reference's plans (a first waypoint
        beyond MIS_DIST_1WP still flies); a waypoint outside the geofence does (checkMissionAgainstGeofence)."""
        return self.fence_violation is None and self.count(PLAN_MISSION) > 0

    def mission_state(self, mode_active: bool = False) -> int:
        """MISSION_CURRENT.mission_state (mavlink_mission.cpp update_mission_state): COMPLETE once the navigator
        finished it, ACTIVE in a mode that flies it, PAUSED outside one after an item was reached."""
        if not self.count(PLAN_MISSION):
            return MISSION_STATE_NO_MISSION
        if self.finished:
            return MISSION_STATE_COMPLETE
        if mode_active:
            return MISSION_STATE_ACTIVE
        if self.seq_reached >= 0:
            return MISSION_STATE_PAUSED
        return MISSION_STATE_NOT_STARTED
