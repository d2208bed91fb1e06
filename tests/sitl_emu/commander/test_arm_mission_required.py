"""COM_ARM_MIS_REQ on the vehicle (HealthAndArmingChecks/checks/modeCheck.cpp): with 1 and no valid mission stored,
arming is denied in every mode (PX4's "Arming denied: Resolve system health failures first", the health report's
check_modes_mission for all modes, HEARTBEAT UNINIT); a valid mission makes it armable; the default 0 arms in Hold
without a mission, as before."""

from __future__ import annotations

from support.events_client import EventsDecoder
from support.flights import command

from sitl_emu.events.metadata import events_metadata
from sitl_emu.geo import ned_to_global
from sitl_emu.navigator.mission_store import PLAN_MISSION, MissionItem
from sitl_emu.params import default_registry
from sitl_emu.px4 import MavCmd, MavResult, MavState
from sitl_emu.vehicle.vehicle import Vehicle

DECODER = EventsDecoder(events_metadata())
ARM_DENIED = "Arming denied: Resolve system health failures first"
ALL_MODES = 0xFFFFFFFF
REL, WP = 6, 16


def _vehicle(mission_required: int) -> Vehicle:
    reg = default_registry()
    reg.set("COM_ARM_MIS_REQ", mission_required)
    v = Vehicle(params=reg)
    v.run_for(2.5)
    return v


def _store_a_mission(v: Vehicle) -> None:
    lat, lon, _ = ned_to_global(v.ref, (10.0, 0.0, 0.0))
    v.mission_store().replace(PLAN_MISSION, (MissionItem(0, REL, WP, 1, 0.0, 0.0, 0.0, 0.0, round(lat * 1e7),
                                                         round(lon * 1e7), 5.0),))
    v.run_for(0.5)


def _mission_check_modes(v: Vehicle, after: int) -> list[int]:
    """The modes argument of each check_modes_mission event after PX4 event seq `after`."""
    out = []
    for _, e in v.px4_events_after(after):
        decoded = DECODER.decode(e.id, e.arguments)
        if decoded is not None and decoded[0] == "check_modes_mission":
            out.append(int.from_bytes(e.arguments[:4], "little"))
    return out


def test_without_a_mission_arming_is_denied_in_hold_until_one_is_stored():
    v = _vehicle(1)
    seq = v.last_event_seq
    assert v.commander.system_status() is MavState.UNINIT
    ack = command(v, MavCmd.COMPONENT_ARM_DISARM, 1.0, 0.0)
    assert ack is not None and ack.result == MavResult.TEMPORARILY_REJECTED and not v.snapshot().armed
    assert [e.text for e in v.events_after(seq) if e.statustext] == [ARM_DENIED]
    assert ALL_MODES in _mission_check_modes(v, -1)  # the report: no arming in any mode
    _store_a_mission(v)
    assert v.commander.system_status() is MavState.STANDBY
    ack = command(v, MavCmd.COMPONENT_ARM_DISARM, 1.0, 0.0)
    assert ack is not None and ack.result == MavResult.ACCEPTED and v.snapshot().armed


def test_the_default_arms_in_hold_without_a_mission():
    v = _vehicle(0)
    assert ALL_MODES not in _mission_check_modes(v, -1)
    ack = command(v, MavCmd.COMPONENT_ARM_DISARM, 1.0, 0.0)
    assert ack is not None and ack.result == MavResult.ACCEPTED
