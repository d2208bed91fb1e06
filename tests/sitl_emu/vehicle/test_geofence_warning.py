"""GF_ACTION 1 (Warning) on the vehicle over simulated time: a breach is told once, with PX4 main's event only
(framework.cpp notifyUser: commander_failsafe_enter_generic_warn "Failsafe warning:" at Warning level, the user's
intended mode as its argument; no "Failsafe activated" STATUSTEXT since PX4 #24858), beside geofenceCheck.cpp's
breach text; the mode stays, the vehicle is not in failsafe (HEARTBEAT ACTIVE, PX4 #22879) and flies on; a new
breach after the vehicle came back inside is told again (the Warn action clears with its condition)."""

from __future__ import annotations

import math

from support.events_client import EventsDecoder
from support.flights import command, hovering_vehicle
from support.mission_flight import REL, TAKEOFF, WP, Flight

from sitl_emu.events.library import Log
from sitl_emu.events.metadata import events_metadata
from sitl_emu.geo import ned_to_global
from sitl_emu.navigator.mission_store import PLAN_FENCE, MissionItem
from sitl_emu.px4 import MavCmd, MavState, NavState, custom_mode
from sitl_emu.types import ManualControlSetpoint
from sitl_emu.vehicle.vehicle import Vehicle

DECODER = EventsDecoder(events_metadata())
WARNING = ("commander_failsafe_enter_generic_warn", "Failsafe warning:")
CENTRED = ManualControlSetpoint(throttle=0.0)


def _px4_seq(v: Vehicle) -> int:
    events = v.px4_events_after(-1)
    return events[-1][0] if events else 0


def _warnings(v: Vehicle, after: int) -> list[tuple[bytes, int]]:
    """(arguments, log levels) of each failsafe warning after PX4 event seq `after`."""
    return [(e.arguments, e.log_levels) for _, e in v.px4_events_after(after)
            if DECODER.decode(e.id, e.arguments) == WARNING]


def _texts(v: Vehicle, after: int) -> list[str]:
    return [e.text for e in v.events_after(after) if e.statustext and e.text.startswith(("Geofence", "Failsafe"))]


def _fly(v: Vehicle, seconds: float, sticks: ManualControlSetpoint) -> None:
    end = v.time_us + round(seconds * 1e6)
    while v.time_us < end:
        if v.time_us % 50_000 == 0:
            v.manual_control_input(sticks)
        v.step()


def _distance_m(v: Vehicle) -> float:
    n, e, _ = v.snapshot().pos_ned_m
    return math.hypot(n, e)


def test_position_mode_flown_past_the_limit_warns_once_per_breach_and_flies_on():
    v = hovering_vehicle(GF_ACTION=1, GF_MAX_HOR_DIST=15.0)
    _fly(v, 1.0, CENTRED)
    command(v, MavCmd.DO_SET_MODE, 1, 3, 0)  # Position
    _fly(v, 1.0, CENTRED)
    seq, text_seq = _px4_seq(v), v.last_event_seq
    _fly(v, 8.0, ManualControlSetpoint(throttle=0.0, pitch=1.0))  # full forward, well past 15 m
    s = v.snapshot()
    assert _distance_m(v) > 30.0 and s.nav_state is NavState.POSCTL and s.armed
    assert not v.commander.failsafe and v.commander.system_status() is MavState.ACTIVE
    (arguments, levels), = _warnings(v, seq)
    assert arguments[:4] == custom_mode(NavState.POSCTL).to_bytes(4, "little")
    assert levels == Log.WARNING << 4 | Log.WARNING
    assert _texts(v, text_seq) == ["Geofence: exceeding maximum distance to Home"]  # no "Failsafe activated"
    _fly(v, 12.0, ManualControlSetpoint(throttle=0.0, pitch=-1.0))  # back inside...
    assert _distance_m(v) < 15.0
    _fly(v, 10.0, ManualControlSetpoint(throttle=0.0, pitch=1.0))  # ...and out again: a new breach, told again
    assert _distance_m(v) > 15.0 and v.snapshot().nav_state is NavState.POSCTL
    assert len(_warnings(v, seq)) == 2


def test_a_mission_flown_through_an_exclusion_circle_warns_and_goes_on_to_its_last_waypoint():
    """Both waypoints are outside the no-fly circle (so the mission is feasible); the leg between them crosses it."""
    f = Flight([(TAKEOFF, 0.0, 0.0, 5.0, (), REL), (WP, 40.0, 0.0, 5.0, (), REL), (WP, 40.0, 10.0, 5.0, (), REL)])
    lat, lon, _ = ned_to_global(f.v.ref, (20.0, 0.0, 0.0))
    no_fly = MissionItem(0, REL, MavCmd.NAV_FENCE_CIRCLE_EXCLUSION, 1, 5.0, 0.0, 0.0, 0.0, round(lat * 1e7),
                         round(lon * 1e7), 0.0)
    f.store.replace(PLAN_FENCE, (no_fly,))
    f.v.params.set("GF_ACTION", 1)
    f.start()
    seq, text_seq = _px4_seq(f.v), f.v.last_event_seq
    modes: set[tuple[NavState, bool]] = set()

    def last_waypoint_reached() -> bool:
        if 2 in [i for i, _ in f.reached]:
            return True  # (and the finished mission hands over to Hold)
        modes.add((f.v.snapshot().nav_state, f.v.commander.failsafe))
        return False

    f.run_until(last_waypoint_reached, 90.0)
    assert modes == {(NavState.AUTO_MISSION, False)}  # the mission flew on through the breach, no failsafe
    (arguments, _), = _warnings(f.v, seq)
    assert arguments[:4] == custom_mode(NavState.AUTO_MISSION).to_bytes(4, "little")
    assert _texts(f.v, text_seq) == ["Geofence: approaching or outside geofence"]
