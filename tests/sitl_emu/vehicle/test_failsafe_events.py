"""The failsafe notices as PX4 sends them: framework.cpp notifyUser's events (action, delayed action, delay, cause)
beside the STATUSTEXTs the recordings hold, with the causes failsafe.cpp gives its checks (causedBy
ManualControlLoss / GCSConnectionLoss, fromBatteryWarningActParam's battery levels; mode fallbacks are generic).
Each event decodes with the served metadata (events/metadata.py) into the message a ground station shows."""

from __future__ import annotations

import math

import pytest
from support.events_client import EventsDecoder
from support.flights import command, hovering_vehicle

from sitl_emu.events import failsafe_notices
from sitl_emu.events.metadata import events_metadata
from sitl_emu.px4 import MavCmd, NavState, custom_mode, decode_custom_mode
from sitl_emu.types import OffboardControlMode, TrajectorySetpoint
from sitl_emu.vehicle.vehicle import Vehicle

NAN = math.nan
RTL_ACTION, GCS_CONNECTION_LOSS, CRITICAL_BATTERY = 6, 2, 4
DECODER = EventsDecoder(events_metadata())
NOTICES = {d.name for d in failsafe_notices.DEFINITIONS}


def _notices(v: Vehicle, after: int) -> list[tuple[float, str, str, bytes]]:
    """(time s, name, decoded message, the arguments) of the failsafe notices after PX4 event seq `after`."""
    out = []
    for _, e in v.px4_events_after(after):
        decoded = DECODER.decode(e.id, e.arguments)
        if decoded is not None and decoded[0] in NOTICES:
            out.append((e.time_ms / 1e3, decoded[0], decoded[1], e.arguments))
    return out


def _text_time(v: Vehicle, text: str, after_seq: int) -> float:
    return next(e.time_us for e in v.events_after(after_seq) if e.text == text and e.statustext) / 1e6


def _px4_seq(v: Vehicle) -> int:
    events = v.px4_events_after(-1)
    return events[-1][0] if events else 0


def test_data_link_loss_tells_its_cause_and_the_return_the_hold_delays():
    v = hovering_vehicle(NAV_DLL_ACT=2)
    for _ in range(20):
        v.gcs_heartbeat()
        v.run_for(0.1)
    seq, text_seq = _px4_seq(v), v.last_event_seq
    v.run_for(20.0)
    (hold, act) = _notices(v, seq)[:2]
    assert hold[1:3] == ("commander_failsafe_enter_hold", "GCS connection loss: switching to RTL in 5 seconds")
    loiter = custom_mode(NavState.AUTO_LOITER)  # the user's intended mode, as PX4's custom mode
    assert hold[3][:8] == loiter.to_bytes(4, "little") + bytes([RTL_ACTION, 5, 0, GCS_CONNECTION_LOSS])
    assert hold[0] == pytest.approx(_text_time(v, "Failsafe activated: entering Hold for 5 seconds", text_seq),
                                    abs=0.001)
    assert act[1:3] == ("commander_failsafe_enter", "GCS connection loss: switching to RTL")
    assert act[0] == pytest.approx(hold[0] + 5.0, abs=0.05)
    assert act[0] == pytest.approx(_text_time(v, "Failsafe activated", text_seq), abs=0.001)
    decoded = [DECODER.decode(e.id, e.arguments) for _, e in v.px4_events_after(seq)]
    assert decoded[0] == ("commander_gcs_lost", "Connection to ground control station lost")  # dataLinkCheck
    seq = _px4_seq(v)
    v.gcs_heartbeat()
    v.run_for(0.1)
    assert ("commander_dl_regained", "GCS connection regained") in [
        DECODER.decode(e.id, e.arguments) for _, e in v.px4_events_after(seq)]


def test_a_critical_battery_names_its_level():
    v = hovering_vehicle(SIM_BAT_DRAIN=60.0, SIM_BAT_MIN_PCT=6.0)  # critical (7 %) -> COM_LOW_BAT_ACT 3: Return
    seq = _px4_seq(v)
    v.run_for(60.0)
    notices = _notices(v, seq)
    assert [m for _, _, m, _ in notices][:2] == ["critical battery level: switching to RTL in 5 seconds",
                                                "critical battery level: switching to RTL"]
    assert notices[0][3][7] == CRITICAL_BATTERY  # mode (4 bytes), action, delay (2 bytes), cause
    warnings = [DECODER.decode(e.id, e.arguments) for _, e in v.px4_events_after(seq)]
    assert ("commander_failsafe_enter_low_bat", "Low battery level, return advised") in warnings  # no STATUSTEXT


def test_offboard_loss_is_a_generic_fallback_without_a_hold():
    v = hovering_vehicle()
    mode, sp = OffboardControlMode(position=True), TrajectorySetpoint(position_ned_m=(0.0, 0.0, -2.5))
    v.offboard_input(mode, sp)
    command(v, MavCmd.DO_SET_MODE, 1.0, *decode_custom_mode(custom_mode(NavState.OFFBOARD)))
    v.offboard_input(mode, sp)
    seq = _px4_seq(v)
    v.run_for(3.0)  # the setpoints stopped: COM_OBL_RC_ACT Position cannot run without sticks -> NAV_RCL_ACT Return
    assert v.snapshot().nav_state is NavState.AUTO_RTL
    ((_, name, message, arguments),) = _notices(v, seq)
    assert (name, message) == ("commander_failsafe_enter_generic", "Failsafe activated: switching to RTL")
    assert arguments[:5] == custom_mode(NavState.OFFBOARD).to_bytes(4, "little") + bytes([RTL_ACTION])


@pytest.mark.parametrize(("action", "name"), [(6, "commander_failsafe_enter_generic"),
                                              (7, "commander_failsafe_enter_generic"),
                                              (3, "commander_failsafe_enter_autopilot_disengaged"),
                                              (4, "commander_failsafe_enter_autopilot_disengaged"),
                                              (8, "commander_failsafe_enter_autopilot_disengaged")])
def test_only_an_action_that_leaves_position_control_says_autopilot_disengaged(action, name):
    """framework.cpp notifyUser (PX4 #23543): a generic Return or Land is "Failsafe activated: switching to ...";
    the Altitude and Stabilized fallbacks and Descend keep "Autopilot disengaged"."""
    definition, values = failsafe_notices.failsafe_notice(custom_mode(NavState.POSCTL), action, 0, 0, 0)
    assert definition.name == name and values == (custom_mode(NavState.POSCTL), action)
