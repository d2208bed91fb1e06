"""AUTO.RTL along the mission (RTL_TYPE 1-4): which return RTL_TYPE asks for, and the task that flies the mission
back, on to its landing or its landing from its start (navigator/return_path.py) with FlightTaskAuto's core.

rtl.cpp setRtlTypeAndDestination (PX4 main) for RTL_TYPE 2: a mission with a landing (a land item; its start the first
DO_LAND_START, else the land item: navigator/rally.py land_markers) returns along it forwards (RtlMissionFast), any
other valid mission backwards (RtlMissionFastReverse), no valid mission directly (RtlDirect, rtl.py). RTL_TYPE 4:
forwards only when the landing pattern is nearer than the start (reverseIsFurther), else as 2. RTL_TYPE 1 and 3: when
navigator/rally.py chooses the mission's landing, RtlDirectMissionLand (rtl_direct_mission_land.cpp): from the land
start, a climb to the return altitude (RTL::computeReturnAltitude towards the land item) when lower, then the landing's
items flown as RtlMissionFast flies them, MISSION_CURRENT following, the mode AUTO.RTL throughout; that return altitude
is the one computed when the return type last became the mission landing (MissionLandAltitude).
"""

from __future__ import annotations

from enum import Enum
from typing import Final

from sitl_emu.flight_tasks.core import AutoSettings, Task, Waypoint
from sitl_emu.flight_tasks.mission import mission_settings, mission_waypoint
from sitl_emu.flight_tasks.rtl import _f32, return_altitude_up
from sitl_emu.geo import GeoRef
from sitl_emu.navigator.mission_items import nav_items
from sitl_emu.navigator.mission_store import PLAN_MISSION, MissionItem, MissionStore
from sitl_emu.navigator.rally import ReturnDestination, land_markers
from sitl_emu.navigator.return_path import (
    ForwardMissionNavigator,
    MissionLandNavigator,
    ReturnNavigator,
    ReverseMissionNavigator,
    forward_start_index,
    reverse_start_index,
)
from sitl_emu.navigator.setpoint import NavInput
from sitl_emu.params import ParamRegistry
from sitl_emu.types import NAN

RTL_TYPE_MISSION_FAST: Final = 2  # rtl_params.yaml: "Return by flying along the mission path (forward or backward)"
RTL_TYPE_MISSION_FAST_SHORTEST: Final = 4  # "... whichever way is shorter to the landing"


def land_start_index(items: tuple[MissionItem, ...]) -> int:
    """Where the mission's landing starts when it has one (RTL::hasMissionLandStart: both markers of
    navigator/rally.py land_markers), else -1."""
    land_start, land = land_markers(items)
    return land_start if land >= 0 else -1


RTL_CHECK_PERIOD_US: Final = 2_000_000  # RTL::on_inactive: the return type evaluated at most every 2 s


class MissionLandAltitude:
    """The mission landing's return altitude as PX4 keeps it. RTL::setRtlTypeAndDestination runs every 2 s while
    Return is inactive and once as it starts, but hands the mission landing its return altitude
    (computeReturnAltitude, from where the vehicle is then) only when the return type becomes the mission landing
    (initRtlMissionType): a mission with its landing at home, uploaded on the ground there, keeps the altitude of the
    ground (2 x the distance to the land item), and Return flies to it without climbing."""

    def __init__(self) -> None:
        self.rtl_up_m = NAN  # up, local frame
        self._is_land = False

    def evaluate(self, destination: ReturnDestination | None, nav: NavInput, settings: AutoSettings) -> None:
        """One setRtlTypeAndDestination with the destination chosen (navigator/rally.py)."""
        is_land = destination is not None and destination.mission_land
        if destination is not None and is_land and not self._is_land:
            self.rtl_up_m = return_altitude_up(settings, destination.pos_ned_m, nav.pos_ned_m)
        self._is_land = is_land


class MissionReturn(Enum):
    """The returns along the mission (rtl.h RtlType)."""

    FORWARD = "forward"  # RTL_MISSION_FAST
    REVERSE = "reverse"  # RTL_MISSION_FAST_REVERSE
    LAND = "land"  # RTL_DIRECT_MISSION_LAND


def mission_return(rtl_type: int, store: MissionStore) -> MissionReturn | None:
    """The return RTL_TYPE picks for the stored mission (RTL::setRtlTypeAndDestination), None: RtlDirect."""
    if rtl_type not in (RTL_TYPE_MISSION_FAST, RTL_TYPE_MISSION_FAST_SHORTEST) or not store.mission_valid:
        return None
    land_start = land_start_index(store.plan(PLAN_MISSION).items)
    reverse_is_further = land_start - store.current_seq < store.current_seq
    if land_start >= 0 and (rtl_type == RTL_TYPE_MISSION_FAST or reverse_is_further):
        return MissionReturn.FORWARD
    return MissionReturn.REVERSE


class RtlMissionTask(Task):
    """One activation of AUTO.RTL flying along the mission; the texts, MISSION_CURRENT and MISSION_ITEM_REACHED
    follow its navigator (the mission_result goes to the store as the mission's does)."""

    def __init__(self, nav: NavInput, params: ParamRegistry, store: MissionStore, ref: GeoRef,
                 home_alt_amsl_m: float, way: MissionReturn, mission_seq_prior_rtl: int, rtl_up_m: float = NAN) -> None:
        """`mission_seq_prior_rtl`: the mission's current item if AUTO.MISSION ran just before, else -1; `rtl_up_m`:
        the mission landing's return altitude (up, local frame; MissionLandAltitude)."""
        super().__init__(nav, params)
        self._store = store
        self._mission_settings = mission_settings(params)
        items = nav_items(store.plan(PLAN_MISSION).items, ref, home_alt_amsl_m)
        navigator: ReturnNavigator
        if way is MissionReturn.LAND:
            navigator = MissionLandNavigator(rtl_up_m=rtl_up_m, rtl_alt_amsl_m=_f32(ref.alt_amsl_m + rtl_up_m))
            first = land_start_index(store.plan(PLAN_MISSION).items)
        elif way is MissionReturn.FORWARD:
            navigator, first = ForwardMissionNavigator(), forward_start_index(items, mission_seq_prior_rtl, nav)
        else:
            navigator, first = ReverseMissionNavigator(), reverse_start_index(items, mission_seq_prior_rtl, nav)
        self._navigator = navigator
        navigator.load(items, 0)
        navigator.start(nav, self._mission_settings, first)
        self._publish()

    def _publish(self) -> None:
        navigator, store = self._navigator, self._store
        store.current_seq = navigator.result.seq_current
        store.seq_reached = navigator.result.seq_reached
        store.finished = navigator.result.finished
        for severity, text in navigator.messages:
            self._say(severity, text)
        navigator.messages.clear()

    def _waypoint(self, nav: NavInput) -> Waypoint:
        navigator = self._navigator
        navigator.update(nav, self._mission_settings)
        self._publish()
        return mission_waypoint(navigator.previous, navigator.current, navigator.next, nav)
