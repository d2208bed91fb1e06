"""PX4's events interface (src/modules/mavlink/mavlink_events.cpp, px4_platform_common/events.h, commander's
events::send calls) against a client that follows it as libevents' ReceiveProtocol and decodes with the served
metadata (tests/support/events_client.py)."""

from __future__ import annotations

import re

import pytest
from support.events_client import EventReceiver, EventsDecoder, extra_of
from support.fakes import Harness

from sitl_emu.events import health_events
from sitl_emu.events.catalogue import DEFINITIONS, ENTRIES
from sitl_emu.events.library import event_id, hash_32_fnv1a, sub_id
from sitl_emu.events.metadata import events_metadata
from sitl_emu.mavlink.protocols.events import EventsProtocol
from sitl_emu.px4 import MavCmd
from sitl_emu.vehicle.vehicle import Vehicle

FIRST_SEQUENCE = 65526  # events::initial_event_sequence (65535 - 10) + 1


def test_ids_are_the_24_bit_fnv1a_hash_of_the_name_with_the_autopilot_component():
    assert [hash_32_fnv1a(s) for s in ("", "a", "foobar")] == [0x811C9DC5, 0xE40C292C, 0xBF9CF968]  # FNV-1a vectors
    assert (sub_id("test1"), sub_id("test2")) == (2306236, 2307445)  # libevents' libs/test.json
    assert event_id("commander_armed_by") >> 24 == 1
    assert len({d.id for d in DEFINITIONS}) == len(DEFINITIONS)


@pytest.fixture
def h():
    harness = Harness(Vehicle(), handler_classes=[EventsProtocol])
    harness.gcs.heartbeat()
    harness.io()
    yield harness
    harness.close()


def _events(client):
    return [f for msg_id, f in filter(None, map(extra_of, client.received)) if msg_id == 410]


_REPORT_IDS = {d.id for d in health_events.DEFINITIONS}


def _text_events(client):
    """The events beside the vehicle's texts, without the health and arming check reports (tested on their own)."""
    return [e for e in _events(client) if e["id"] not in _REPORT_IDS]


def _current(client):
    return [f for msg_id, f in filter(None, map(extra_of, client.received)) if msg_id == 411]


def _command(h, command, *params, wait_s=0.1):
    h.gcs.heartbeat()
    h.gcs.command_long(command, *params)
    h.run(wait_s)


def test_the_first_event_comes_after_the_sequence_with_reset_then_commander_armed_by(h):
    h.run(2.5)  # the first health report (2 s after boot) is the first event
    new = [extra_of(m) for m in h.gcs.received]
    seq_reset = [f for m in new if m and m[0] == 411 for f in [m[1]]]
    assert seq_reset[0] == {"sequence": FIRST_SEQUENCE, "flags": 1}
    assert _events(h.gcs)[0]["sequence"] == FIRST_SEQUENCE
    latest = _events(h.gcs)[-1]["sequence"]
    _command(h, MavCmd.COMPONENT_ARM_DISARM, 1)
    (armed,) = _text_events(h.gcs)
    assert armed["id"] == event_id("commander_armed_by") and armed["sequence"] == latest + 1
    assert armed["log_levels"] == 0x66 and armed["arguments"][0] == 4  # Info/Info, command_external
    assert (armed["destination_system"], armed["destination_component"]) == (0, 0)
    assert abs(armed["event_time_boot_ms"] - h.vehicle.time_us // 1000) < 200
    assert EventsDecoder(events_metadata()).decode(armed["id"], armed["arguments"]) == \
        ("commander_armed_by", "Armed by external command")
    assert _text_events(h.api) == [armed]  # every link sends it, with the same sequence


def test_refusals_carry_their_arguments(h):
    _command(h, MavCmd.COMPONENT_ARM_DISARM, 1)  # not ready yet
    h.run(2.5)
    _command(h, MavCmd.COMPONENT_ARM_DISARM, 1)
    _command(h, MavCmd.DO_SET_MODE, 1, 6, 0)  # armed, OFFBOARD without setpoints, from QGC's component
    decoder = EventsDecoder(events_metadata())
    decoded = [decoder.decode(e["id"], e["arguments"]) for e in _text_events(h.gcs)]
    assert decoded == [("commander_arm_denied_resolve_failures", "Arming denied: Resolve system health failures first"),
                       ("commander_armed_by", "Armed by external command"),
                       ("commander_modeswitch_not_avail", "Switching to mode 'Offboard' is currently not possible")]
    refused = _text_events(h.gcs)[2]
    assert refused["log_levels"] == 0x62  # {Critical, LogInternal::Info}
    assert bytes(refused["arguments"][:5]) == (6 << 16).to_bytes(4, "little") + bytes([7])  # custom_mode, offboard


def test_current_sequence_with_reset_before_the_first_event_then_every_3_s():
    h = Harness(Vehicle(), handler_classes=[EventsProtocol])
    try:
        h.run(1.9)
        assert _current(h.gcs) == [] and _events(h.gcs) == []
        h.run(8.1)  # the first event (the health report at 2 s) after a RESET; then every 3 s, at 5 and 8 s
        latest = _events(h.gcs)[-1]["sequence"]
        assert _current(h.gcs) == [{"sequence": FIRST_SEQUENCE, "flags": 1}] + [{"sequence": latest, "flags": 0}] * 2
        h.gcs.heartbeat()
        h.run(0.1)
        assert len(_current(h.gcs)) == 3  # a GCS appearing changes nothing (PX4 SIH: 0.33 Hz, nothing more)
    finally:
        h.close()


def test_request_event_answers_from_the_last_20_and_an_error_for_older(h):
    h.run(2.5)
    for _ in range(11):  # 22 events: the sequence wraps past 65535 and the buffer drops the first 2
        _command(h, MavCmd.COMPONENT_ARM_DISARM, 1)
        _command(h, MavCmd.COMPONENT_ARM_DISARM, 0)
    sent = _events(h.gcs)  # the health report at 2 s, then the 22
    assert len(_text_events(h.gcs)) == 22 and len(sent) > 22
    assert [e["sequence"] for e in sent] == [(FIRST_SEQUENCE + i) & 0xFFFF for i in range(len(sent))]
    h.run(3.0)  # a CURRENT_EVENT_SEQUENCE announces the newest
    announced = [m for m in h.gcs.received if (extra_of(m) or (0,))[0] == 411][-1]
    receiver = EventReceiver(h.gcs)
    receiver.latest = (FIRST_SEQUENCE - 1) & 0xFFFF  # a client that heard none of them
    start = len(h.gcs.received)
    receiver.feed([announced])  # asks for the first it missed
    for _ in range(40):  # follow the protocol: each answer brings the next request
        h.run(0.02)
        receiver.feed(h.gcs.received[start:])
        start = len(h.gcs.received)
    assert receiver.lost == len(sent) - 20  # one RESPONSE_EVENT_ERROR named the oldest still held
    assert [e["sequence"] for e in receiver.events] == [e["sequence"] for e in sent[-20:]]
    assert [(e["id"], e["arguments"]) for e in receiver.events] == [(e["id"], e["arguments"]) for e in sent[-20:]]


def test_a_request_for_a_missing_event_gets_response_event_error(h):
    h.run(2.5)
    _command(h, MavCmd.COMPONENT_ARM_DISARM, 1)
    h.gcs.received.clear()
    EventReceiver(h.gcs).request(FIRST_SEQUENCE - 5, FIRST_SEQUENCE)
    h.run(0.05)
    replies = [m for m in map(extra_of, h.gcs.received) if m and m[0] in (410, 413)]
    assert [m[0] for m in replies] == [413] * 5 + [410]
    first_error = replies[0][1]
    assert first_error == {"target_system": 255, "target_component": 190, "sequence": FIRST_SEQUENCE - 5,
                           "sequence_oldest_available": FIRST_SEQUENCE, "reason": 0}
    assert replies[5][1]["sequence"] == FIRST_SEQUENCE


@pytest.mark.parametrize("entry", [e for e in ENTRIES if not e.definition.arguments], ids=lambda e: e.definition.name)
def test_an_event_without_arguments_goes_with_its_statustext(entry):
    from sitl_emu.events.catalogue import to_px4_event
    from sitl_emu.px4 import Severity
    from sitl_emu.types import VehicleEvent

    text = re.sub(r"\\(.)", r"\1", entry.text.pattern)  # the exact text the entry matches
    definition = entry.definition
    statustext = entry.statustext is not False  # the takeover's two events: with and without a STATUSTEXT
    event = to_px4_event(VehicleEvent(1, 2_000_000, Severity.INFO, "commander", text, statustext=statustext))
    assert event is not None and event.id == definition.id and event.time_ms == 2000
    assert EventsDecoder(events_metadata()).decode(event.id, event.arguments) == (definition.name, definition.message)
    assert to_px4_event(VehicleEvent(1, 0, Severity.INFO, "commander", text, is_event=False)) is None


def _fly(h, seconds):
    for _ in range(round(seconds)):  # QGC's heartbeat each second: the STATUSTEXTs go out too
        h.gcs.heartbeat()
        h.run(1.0)


def test_a_flight_sends_takeoff_landing_and_the_disarm_by_landing(h):
    h.run(2.5)
    _command(h, MavCmd.COMPONENT_ARM_DISARM, 1)
    _command(h, MavCmd.NAV_TAKEOFF)
    _fly(h, 6.0)
    _command(h, MavCmd.NAV_LAND)
    _fly(h, 12.0)
    decoder = EventsDecoder(events_metadata())
    messages = [decoder.decode(e["id"], e["arguments"])[1] for e in _text_events(h.gcs)]
    assert messages == ["Armed by external command", "Using default takeoff altitude: 2.50 m", "Takeoff detected",
                        "Landing at current position", "Landing detected", "Disarmed by landing"]
    messages.remove("Using default takeoff altitude: 2.50 m")  # PX4's text says 2.5 m, the event {1:.2m}
    texts = [m.text.rstrip("\t") for m in h.gcs.of_type("STATUSTEXT") if m.text.endswith("\t")]
    assert [t for t in texts if t in messages] == messages  # each beside its tab-terminated STATUSTEXT


def test_a_request_for_this_vehicle_is_not_forwarded_to_the_other_link(h):
    h.api.heartbeat()  # the API link has heard a component: broadcasts reach it
    h.run(0.05)
    EventReceiver(h.gcs).request(FIRST_SEQUENCE)
    h.run(0.05)
    EventReceiver(h.gcs, target=(0, 0)).request(FIRST_SEQUENCE)
    h.run(0.05)
    forwarded = [x[1] for x in map(extra_of, h.api.received) if x and x[0] == 412]
    assert [(r["target_system"], r["target_component"]) for r in forwarded] == [(0, 0)]


def test_rtl_start_carries_both_altitudes_as_px4s_vrtl_return_at():
    from sitl_emu.events.catalogue import to_px4_event
    from sitl_emu.px4 import Severity
    from sitl_emu.types import VehicleEvent

    text = "RTL: start return at 519 m (31 m above destination)"
    event = to_px4_event(VehicleEvent(1, 0, Severity.INFO, "navigator", text))
    assert event is not None and event.id == event_id("vrtl_return_at")
    assert EventsDecoder(events_metadata()).decode(event.id, event.arguments) == ("vrtl_return_at", text)
