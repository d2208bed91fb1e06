"""The flight session's vocabulary: phases, settings, notes to the user, flight statistics and the view snapshot the
live view draws. Plain data and one pure statistics update; the session itself is joyfly/flight.py."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from enum import Enum
from typing import Protocol

from joyfly.link import VehicleState
from joyfly.setpoints import Fence, Limits, Setpoint
from joyfly.types import StickCommand


class Phase(Enum):
    CONNECTING = "connecting"
    PRESTREAM = "pre-streaming setpoints"
    ARMING = "arming"
    ENTERING = "entering OFFBOARD"
    RESUMING = "resuming the setpoint stream"
    FLYING = "flying in OFFBOARD"
    PAUSED = "not commanding"
    LANDING = "landing"
    GROUNDED = "landed"
    EXITING = "exiting"
    DONE = "done"
    FAILED = "failed"


STREAMING_PHASES = (Phase.PRESTREAM, Phase.ARMING, Phase.ENTERING, Phase.RESUMING, Phase.FLYING)


class StickSource(Protocol):
    """Normalised stick commands (the joystick side's mapping output), read without blocking longer than asked."""

    def poll(self, timeout_s: float) -> StickCommand: ...

    def close(self) -> None: ...


@dataclass(frozen=True, slots=True)
class SessionSettings:
    alt_m: float = 3.0
    rate_hz: float = 20.0
    on_exit: str = "land"  # land | hold | rtl
    joy_timeout_s: float = 5.0
    connect_timeout_s: float = 15.0
    prestream_count: int = 10  # setpoints sent before arming (the seed node sends its first ones the same way)
    arm_attempts: int = 3
    exit_timeout_s: float = 60.0
    exit_when_landed: bool = False  # `joyfly demo`: finish once the vehicle has landed and disarmed
    fence_m: float = 5.0
    min_alt_m: float = 0.5
    max_alt_m: float = 10.0
    limits: Limits = field(default_factory=Limits)


@dataclass(frozen=True, slots=True)
class Note:
    time_s: float
    level: str  # info | warn | error
    text: str


@dataclass(frozen=True, slots=True)
class FlightStats:
    distance_m: float = 0.0
    min_fence_margin_m: float = math.inf
    offboard_time_s: float = 0.0
    max_alt_m: float = 0.0


@dataclass(frozen=True, slots=True)
class SessionView:
    """Everything the live view shows, one consistent snapshot."""

    time_s: float
    phase: Phase
    link_ok: bool
    mode: str
    armed: bool
    landed_state: int
    pos_ned_m: tuple[float, float, float] | None
    setpoint: Setpoint | None
    streaming: bool
    stick: StickCommand
    joystick_ok: bool
    fence: Fence
    stats: FlightStats
    statustexts: tuple[str, ...]
    notes: tuple[Note, ...]
    link_description: str


def update_stats(stats: FlightStats, prev_pos: tuple[float, float, float] | None, st: VehicleState, fence: Fence,
                 dt_s: float) -> FlightStats:
    """Accumulate distance flown, closest approach to the fence (in the air) and time in OFFBOARD, while armed."""
    pos = st.pos_ned_m
    if pos is None or not st.armed:
        return stats
    dist = stats.distance_m + (math.dist(pos, prev_pos) if prev_pos is not None else 0.0)
    in_air = st.landed_state != 1
    margin = min(stats.min_fence_margin_m, fence.margin_m(pos)) if in_air else stats.min_fence_margin_m
    offboard = stats.offboard_time_s + (dt_s if st.offboard else 0.0)
    return FlightStats(dist, margin, offboard, max(stats.max_alt_m, fence.alt_m(pos)))


def no_vehicle_message(where: str, heard: bool, timeout_s: float) -> str:
    """Why the session could not start, and what to do about it."""
    if heard:
        return (f"The vehicle on {where} sends HEARTBEATs but no LOCAL_POSITION_NED after {timeout_s:g} s: it has "
                "no position estimate yet; wait for it, then retry.")
    return (f"No HEARTBEAT from a vehicle on {where} after {timeout_s:g} s: start `sitl-emu serve` or PX4 SITL "
            "first (PX4 sends to UDP port 14540), or fix --url.")


def left_offboard_message(mode: str, recent_texts: list[str]) -> str:
    why = f" ({recent_texts[-1]})" if recent_texts else ""
    return (f"The vehicle left OFFBOARD for {mode}{why}: joyfly stopped sending setpoints and will not fight it; "
            "press OFFBOARD to take control again.")
