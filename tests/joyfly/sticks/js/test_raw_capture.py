"""Issue 25.1: what is not a js_event stream never flies. The record check (JsStreamCheck), `raw:FILE` captures
(checked at open, played with their own timing, gone at their end) and a FIFO fed something else; then the session:
a source gone before arming ends it with one sentence, a capture that ends in flight is a lost joystick."""

from __future__ import annotations

import os
import random
from pathlib import Path

import pytest
from support.joyfly_fakes import FakeVehicle
from support.joyfly_sim import SimClock, memory_pair

from joyfly.link.vehicle_link import VehicleLink
from joyfly.run import closing_status
from joyfly.session.core import Phase, SessionSettings
from joyfly.session.flight_session import FlightSession
from joyfly.sticks.js.events import (
    JS_EVENT_AXIS,
    JS_EVENT_BUTTON,
    JS_EVENT_INIT,
    JoystickError,
    JsStreamCheck,
    pack_event,
    parse_events,
)
from joyfly.sticks.js.raw_capture import capture_steps
from joyfly.sticks.js.reader import open_joystick
from joyfly.sticks.mapping import open_sticks

AXES, BUTTONS = 4, 7  # the script profile's layout (joyfly script), so captures map without a --profile


def init_burst(time_ms: int = 0) -> bytes:
    return b"".join([pack_event(JS_EVENT_BUTTON | JS_EVENT_INIT, i, 0, time_ms) for i in range(BUTTONS)]
                    + [pack_event(JS_EVENT_AXIS | JS_EVENT_INIT, i, 0, time_ms) for i in range(AXES)])


def at_rest_capture(span_s: float, every_s: float = 0.5) -> bytes:
    """A joystick at rest for span_s: its INIT burst, then a centred axis 0 re-reported every `every_s`."""
    moves = [pack_event(JS_EVENT_AXIS, 0, 0, round(1000 * k * every_s)) for k in range(1, int(span_s / every_s) + 1)]
    return init_burst() + b"".join(moves)


def why(*records: bytes, axes: int = 0, buttons: int = 0) -> str | None:
    check = JsStreamCheck(axes, buttons)
    events, _ = parse_events(b"".join(records))
    for ev in events:
        reason = check.check(ev)
        if reason is not None:
            return reason
    return None


# ------------------------------------------------------------------------------------------------ the record check


def test_records_joydev_writes_pass() -> None:
    assert why(init_burst(5), pack_event(JS_EVENT_AXIS, 3, -32767, 9), pack_event(JS_EVENT_BUTTON, 6, 1, 9),
               init_burst(20)) is None  # a second INIT burst: the kernel's queue overflowed
    assert why(pack_event(JS_EVENT_AXIS, 1, 5, 0xFFFF_FFF0), pack_event(JS_EVENT_AXIS, 1, 6, 0x10)) is None  # u32 wrap


@pytest.mark.parametrize(("record", "fragment"), [
    (pack_event(0x04, 0, 0), "type 0x04, where a js_event has 0x01 (button) or 0x02 (axis)"),
    (pack_event(0x00, 0, 0), "type 0x00"),
    (pack_event(JS_EVENT_BUTTON, 2, 7), "button 2 at 7, where a button is 0 or 1"),
    (pack_event(JS_EVENT_AXIS, 4, 0, 1000), "axis 4, where the joystick has 4 axes"),  # the INIT burst declared 4
    (pack_event(JS_EVENT_BUTTON, 7, 1, 1000), "button 7, where the joystick has 7 buttons"),
    (pack_event(JS_EVENT_AXIS, 0, 0, time_ms=999), "time 999 ms, before the 1000 ms of the record before it"),
])
def test_records_joydev_never_writes_are_named(record: bytes, fragment: str) -> None:
    reason = why(init_burst(1000), record)
    assert reason is not None and fragment in reason


def test_the_counts_a_device_declares_bound_its_numbers() -> None:
    assert why(pack_event(JS_EVENT_AXIS, 2, 0), axes=2, buttons=1) == "axis 2, where the joystick has 2 axes"
    assert why(pack_event(JS_EVENT_AXIS, 70, 0)) == "axis 70, where the joystick has 64 axes"  # none declared


def test_random_bytes_fail_within_their_first_records() -> None:
    for seed in range(50):
        data = random.Random(seed).randbytes(4096)
        assert why(data) is not None, seed


# ------------------------------------------------------------------------------------------------------- raw:FILE


def test_a_capture_of_random_bytes_is_refused_at_open_in_one_sentence(tmp_path: Path) -> None:
    path = tmp_path / "rand.bin"
    path.write_bytes(random.Random(25).randbytes(4096))
    with pytest.raises(JoystickError) as info:
        open_joystick(f"raw:{path}", SimClock())
    text = str(info.value)
    assert text.startswith(f"raw:{path} is not a joystick capture: record 1 (byte 0) has type 0x")
    assert "cat /dev/input/js0 > FILE" in text and "\n" not in text and ". " not in text and text.endswith(".")


@pytest.mark.parametrize(("data", "fragment"), [(b"", "holds no js_event record (0 bytes"),
                                                (init_burst() + b"\x01\x02", "ends in a piece of a record (90 bytes")])
def test_an_empty_or_cut_capture_is_refused(tmp_path: Path, data: bytes, fragment: str) -> None:
    path = tmp_path / "cap.bin"
    path.write_bytes(data)
    with pytest.raises(JoystickError, match=fragment.replace("(", r"\(")):
        open_joystick(f"raw:{path}", SimClock())


def test_a_bad_record_deep_in_a_capture_is_found_before_anything_plays() -> None:
    data = at_rest_capture(3.0) + pack_event(JS_EVENT_AXIS, 0, 0, time_ms=100)  # time runs backwards at the end
    with pytest.raises(JoystickError, match=r"record 18 \(byte 136\) has time 100 ms"):
        capture_steps(data, "raw:cap.bin")


def test_a_capture_plays_for_its_span_then_is_gone(tmp_path: Path) -> None:
    path = tmp_path / "cap.bin"
    path.write_bytes(at_rest_capture(2.0))
    clock = SimClock()
    sticks = open_sticks(f"raw:{path}", clock)
    assert sticks.name == str(path) and sticks.gone() is None
    seen = []
    while clock.now() < 3.0:
        cmd = sticks.poll(0.1)
        seen.append((cmd.time_s, cmd.connected))
    assert all(connected for t, connected in seen if t < 1.99) and not seen[-1][1]
    assert min(t for t, connected in seen if not connected) == pytest.approx(2.0)
    assert sticks.gone() is not None and "reached its end (its records span 2.0 s)" in str(sticks.gone())


# ------------------------------------------------------------------------------------------------------- FIFO


def test_a_fifo_fed_random_bytes_stops_being_read_and_says_why(tmp_path: Path) -> None:
    path = tmp_path / "js0"
    os.mkfifo(path)
    src = open_joystick(str(path), SimClock())
    writer = os.open(path, os.O_WRONLY)
    try:
        os.write(writer, init_burst() + bytes([0, 0, 0, 0, 0, 0, 0x41, 0]))
        state = src.poll(0.5)
    finally:
        os.close(writer)
    assert not state.connected and state.axes == (0,) * AXES  # the good records before it were read
    assert f"{path} sends something other than js_event records (record 12 has type 0x41" in str(src.gone)
    src.close()


# ------------------------------------------------------------------------------------------------------- sessions


def session_with(sticks: object, **settings: object) -> tuple[FlightSession, FakeVehicle, SimClock]:
    clock = SimClock(max_step_s=0.005)
    ours, theirs = memory_pair()
    vehicle = FakeVehicle(theirs)
    clock.on_advance(vehicle.step)
    session = FlightSession(VehicleLink(ours, clock), sticks, clock, SessionSettings(**settings))  # type: ignore[arg-type]
    return session, vehicle, clock


def run(session: FlightSession, clock: SimClock, until_s: float) -> None:
    while not session.finished and clock.now() < until_s:
        session.run_once()


def test_a_fifo_that_turns_out_not_to_carry_js_events_ends_the_session_before_arming(tmp_path: Path) -> None:
    path = tmp_path / "js0"
    os.mkfifo(path)
    sticks = open_sticks(str(path), SimClock())
    writer = os.open(path, os.O_WRONLY)
    os.write(writer, random.Random(3).randbytes(512))
    session, vehicle, clock = session_with(sticks)
    sticks.source.clock = clock  # type: ignore[attr-defined]
    try:
        run(session, clock, 20.0)
    finally:
        os.close(writer)
    assert session.phase is Phase.FAILED and not vehicle.armed and not vehicle.received("CMD400")
    assert session.error is not None and session.error.startswith(f"{path} sends something other than js_event")
    assert closing_status(session, None) == 2  # a mistake in the joystick, as README's exit statuses (and raw:)


def test_a_capture_that_ends_in_flight_is_a_lost_joystick_hold_then_land(tmp_path: Path) -> None:
    path = tmp_path / "cap.bin"
    path.write_bytes(at_rest_capture(8.0))
    session, vehicle, clock = session_with(None, joy_timeout_s=3.0)
    session.sticks = open_sticks(f"raw:{path}", clock)
    run(session, clock, 7.9)
    assert session.phase is Phase.FLYING and vehicle.armed and -vehicle.pos[2] > 2.0
    run(session, clock, 9.0)
    notes = "\n".join(n.text for n in session.notes)
    assert "reached its end (its records span 8.0 s)" in notes and "Joystick lost: holding position" in notes
    assert session.phase is Phase.FLYING and vehicle.armed  # holding, for --joy-timeout
    run(session, clock, 40.0)
    notes = "\n".join(n.text for n in session.notes)
    assert "Joystick still lost after 3 s: landing." in notes and vehicle.received("CMD21")
    assert session.phase is Phase.DONE and not vehicle.armed and "The joystick is gone" in notes
    assert closing_status(session, None) == 0  # in flight the joystick was lost, and the vehicle landed safely


def test_a_capture_that_ended_before_the_flight_ends_the_session_in_one_sentence(tmp_path: Path) -> None:
    path = tmp_path / "cap.bin"
    path.write_bytes(init_burst())  # a joystick at rest sends nothing after its INIT burst: a capture of 0 s
    session, vehicle, clock = session_with(None)
    session.sticks = open_sticks(f"raw:{path}", clock)
    run(session, clock, 20.0)
    assert session.phase is Phase.FAILED and not vehicle.received("CMD400")
    assert session.error is not None and "reached its end (its records span 0.0 s)" in session.error
