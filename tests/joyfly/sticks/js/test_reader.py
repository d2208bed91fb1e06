"""The js API reader: event parsing, FIFO and file sources, a pty standing in for a device, errors."""

from __future__ import annotations

import contextlib
import errno
import os
import tty

import pytest

from joyfly.sticks.js import reader
from joyfly.sticks.js.reader import (
    EVENT_SIZE,
    JS_EVENT_AXIS,
    JS_EVENT_BUTTON,
    JS_EVENT_INIT,
    DeviceVanishedError,
    JoystickError,
    JsDevice,
    list_devices,
    open_joystick,
    pack_event,
    parse_events,
)


class FakeClock:
    def __init__(self) -> None:
        self.t_s = 100.0

    def now(self) -> float:
        return self.t_s

    def sleep(self, seconds: float) -> None:
        self.t_s += max(0.0, seconds)


def init_burst(axes: list[int], buttons: list[int]) -> bytes:
    """What the kernel sends on open: buttons first, then axes, all flagged JS_EVENT_INIT."""
    out = [pack_event(JS_EVENT_BUTTON | JS_EVENT_INIT, i, v) for i, v in enumerate(buttons)]
    out += [pack_event(JS_EVENT_AXIS | JS_EVENT_INIT, i, v) for i, v in enumerate(axes)]
    return b"".join(out)


def test_event_record_is_8_bytes_and_round_trips():
    data = pack_event(JS_EVENT_AXIS, 4, -32767, time_ms=123456) + pack_event(JS_EVENT_BUTTON | JS_EVENT_INIT, 7, 1)
    assert EVENT_SIZE == 8 and len(data) == 16
    events, rest = parse_events(data + b"\x01\x02\x03")
    assert rest == b"\x01\x02\x03"
    first, second = events
    assert (first.time_ms, first.value, first.number, first.type & JS_EVENT_INIT) == (123456, -32767, 4, 0)
    assert (second.type & ~JS_EVENT_INIT, second.number, second.value) == (1, 7, 1)
    assert second.type & JS_EVENT_INIT  # flagged as part of the initial state


def test_fifo_without_writer_opens_at_once_then_reads_events_and_loses_the_writer(tmp_path):
    path = str(tmp_path / "js-fifo")
    os.mkfifo(path)
    clock = FakeClock()
    src = open_joystick(path, clock)  # must not block although nobody writes yet
    assert src.name == path and src.path == path
    assert src.poll(0.0).connected is False  # nothing attached yet

    writer = os.open(path, os.O_WRONLY)
    os.write(writer, init_burst([0, 0, -32767, 0, 0, -32767], [0] * 11))
    state = src.poll(0.5)
    assert state.connected is True
    assert state.axes == (0, 0, -32767, 0, 0, -32767)  # counts grew with the events
    assert len(state.buttons) == 11

    os.write(writer, pack_event(JS_EVENT_AXIS, 4, -32767) + pack_event(JS_EVENT_BUTTON, 7, 1))
    state = src.poll(0.5)
    assert state.axes[4] == -32767 and state.buttons[7] == 1
    assert state.time_s == clock.now()

    os.close(writer)
    state = src.poll(0.5)
    assert state.connected is False
    assert "vanished" in str(src.last_error)

    writer = os.open(path, os.O_WRONLY)  # a new writer is picked up again
    os.write(writer, init_burst([1000], [1]))
    state = src.poll(0.5)
    assert state.connected is True and state.axes == (1000,) and state.buttons == (1,)
    os.close(writer)
    src.close()


def test_fifo_split_record_is_joined(tmp_path):
    path = str(tmp_path / "js-fifo")
    os.mkfifo(path)
    src = open_joystick(path, FakeClock())
    writer = os.open(path, os.O_WRONLY)
    record = pack_event(JS_EVENT_AXIS, 1, 12345)
    os.write(writer, record[:3])
    src.poll(0.2)
    os.write(writer, record[3:])
    assert src.poll(0.2).axes == (0, 12345)
    os.close(writer)
    src.close()


def test_raw_file_is_a_capture_played_with_its_own_timing(tmp_path):
    """raw:FILE used to be read like `tail -f`, for ever: now its records play at their own times, then it is gone."""
    path = tmp_path / "events.bin"
    path.write_bytes(init_burst([0, 0], [0, 0]) + pack_event(JS_EVENT_AXIS, 1, -20000, time_ms=500))
    clock = FakeClock()
    src = open_joystick(f"raw:{path}", clock)
    assert src.name == str(path) and src.path == str(path)
    state = src.poll(0.1)
    assert state.axes == (0, 0) and state.connected
    state = src.poll(1.0)  # waits for the record due at 0.5 s, which is the last: the capture ends with it
    assert state.axes == (0, -20000) and not state.connected
    assert clock.now() - 100.0 == pytest.approx(0.5)
    src.close()


def test_a_stream_of_zeros_is_no_joystick_and_is_not_read_again():
    """raw:/dev/zero (or /dev/urandom) never runs dry: its first record (type 0x00) is no js_event, so joyfly stops
    reading it at once, and says why (it used to take the zeros for axis 0 at rest and fly on them)."""
    clock = FakeClock()
    src = open_joystick("raw:/dev/zero", clock)
    for _ in range(3):
        assert src.poll(0.1).connected is False
    assert "/dev/zero sends something other than js_event records (record 1 has type 0x00" in str(src.gone)
    assert src.fileno() is None
    clock.sleep(5.0)
    assert src.poll(0.1).connected is False  # never reopened
    src.close()


@pytest.fixture
def pty_device():
    """A pty slave is a character device: it stands in for /dev/input/jsN (the js ioctls fail on it)."""
    master, slave = os.openpty()
    tty.setraw(slave)
    path = os.ttyname(slave)
    yield master, path
    os.close(slave)
    with contextlib.suppress(OSError):
        os.close(master)


def test_character_device_without_js_ioctls_falls_back_to_path_name(pty_device):
    master, path = pty_device
    src = JsDevice(path, FakeClock())
    assert src.kind == "device" and src.name == path and src.connected
    os.write(master, init_burst([0, 0, 0], [0, 0]) + pack_event(JS_EVENT_AXIS, 2, 32767))
    assert src.poll(0.5).axes == (0, 0, 32767)
    src.close()


def test_device_read_error_disconnects_then_reopens(pty_device, monkeypatch):
    master, path = pty_device
    clock = FakeClock()
    src = JsDevice(path, clock)
    os.write(master, init_burst([5], [1]))
    assert src.poll(0.5).axes == (5,)

    real_read = os.read

    def unplugged(fd, n):
        raise OSError(errno.ENODEV, "No such device")

    monkeypatch.setattr(reader.os, "read", unplugged)
    os.write(master, pack_event(JS_EVENT_AXIS, 0, 7))
    state = src.poll(0.5)
    assert state.connected is False
    assert str(src.last_error).startswith(f"The joystick {path} vanished")

    monkeypatch.setattr(reader.os, "read", real_read)
    real_open = os.open

    def gone(p, flags):
        raise FileNotFoundError(errno.ENOENT, "No such file")

    monkeypatch.setattr(reader.os, "open", gone)
    clock.sleep(0.5)
    assert src.poll(0.1).connected is False  # the node is gone: still "vanished", not "no such device"
    assert isinstance(src.last_error, DeviceVanishedError)

    monkeypatch.setattr(reader.os, "open", real_open)
    state = src.poll(0.1)  # retries at most every 0.5 s
    assert state.connected is False
    clock.sleep(0.5)
    state = src.poll(0.1)
    assert state.connected is True
    assert src.last_error is None
    src.close()


def test_missing_device_names_the_others_or_says_none(tmp_path):
    with pytest.raises(JoystickError) as info:
        open_joystick(str(tmp_path / "js0"), FakeClock(), dev_dir=str(tmp_path))
    assert "none is connected" in str(info.value) and "script:" in str(info.value)

    os.mkfifo(tmp_path / "js1")
    with pytest.raises(JoystickError) as info:
        open_joystick(str(tmp_path / "js0"), FakeClock(), dev_dir=str(tmp_path))
    assert str(tmp_path / "js1") in str(info.value)
    assert str(info.value).count(".") >= 1 and "\n" not in str(info.value)


def test_permission_denied_says_how_to_fix(tmp_path, monkeypatch):
    def denied(path, flags):
        raise PermissionError(errno.EACCES, "Permission denied")

    monkeypatch.setattr(reader.os, "open", denied)
    with pytest.raises(JoystickError) as info:
        open_joystick("/dev/input/js0", FakeClock())
    message = str(info.value)
    assert "sudo chmod a+rw /dev/input/js0" in message and "input group" in message and "udev" in message


def test_list_devices_reports_each_node(tmp_path):
    os.mkfifo(tmp_path / "js0")
    os.mkfifo(tmp_path / "js10")
    os.mkfifo(tmp_path / "js2")
    found = list_devices(str(tmp_path))
    assert [d.path for d in found] == [str(tmp_path / n) for n in ("js0", "js2", "js10")]
    assert all(d.kind == "fifo" and d.axes == 0 for d in found)


def test_init_burst_after_a_queue_overflow_replaces_the_state(tmp_path):
    path = tmp_path / "events.bin"
    # button 0 pressed and axis 1 pushed; then the queue overflows while they are released: the kernel re-sends
    # the whole state as INIT events, which must win over the stale values.
    path.write_bytes(
        init_burst([0, 0], [0])
        + pack_event(JS_EVENT_BUTTON, 0, 1)
        + pack_event(JS_EVENT_AXIS, 1, -32767)
        + init_burst([0, 0], [0])
    )
    state = open_joystick(f"raw:{path}", FakeClock()).poll(0.0)
    assert state.axes == (0, 0) and state.buttons == (0,)


# ------------------------------------------------------------------------------- what may be a joystick (issue 10)


def _one_sentence(exc: JoystickError) -> str:
    text = str(exc)
    assert "\n" not in text and text.endswith(".") and ". " not in text, text
    return text


@pytest.mark.parametrize("content", [b"Flight notes: take off at the field.\n", bytes(range(256)) * 8,
                                     pack_event(JS_EVENT_AXIS, 0, 32767) * 8, b""],
                         ids=["text", "binary", "js-records", "empty"])
def test_a_regular_file_not_named_raw_is_refused_at_open(tmp_path, content):
    """A text file, a binary file, even well-formed js_event records: joyfly cannot tell a joystick stream from a
    file that happens to parse, so only a --record recording or `raw:FILE` is read."""
    path = tmp_path / "notes.txt"
    path.write_bytes(content)
    with pytest.raises(JoystickError) as info:
        open_joystick(str(path), FakeClock())
    text = _one_sentence(info.value)
    assert f"{path} is a regular file" in text and f"raw:{path}" in text and "--record" in text


def test_a_directory_is_refused_at_once_even_as_raw(tmp_path):
    for spec in (str(tmp_path), f"raw:{tmp_path}"):
        with pytest.raises(JoystickError) as info:
            open_joystick(spec, FakeClock())
        assert _one_sentence(info.value).startswith(f"{tmp_path} is a directory, not a joystick")


def test_dev_null_is_a_character_device_but_not_a_joystick():
    with pytest.raises(JoystickError) as info:
        open_joystick("/dev/null", FakeClock())
    text = _one_sentence(info.value)
    assert text.startswith("/dev/null is a character device but not a joystick") and "raw:/dev/null" in text


def test_raw_vouches_for_a_character_device_without_js_ioctls():
    src = open_joystick("raw:/dev/null", FakeClock())
    assert src.name == "/dev/null" and src.kind == "device"
    src.close()


def test_a_raw_device_that_reads_empty_before_any_record_is_gone_for_good():
    """raw:/dev/null used to wait for ever, 'a FIFO needs its writer': a device that ends before its first record
    is no joystick, and the session refuses it before arming (its `gone`)."""
    clock = FakeClock()
    src = open_joystick("raw:/dev/null", clock)
    assert src.poll(0.1).connected is False
    assert str(src.gone).startswith("raw:/dev/null ended before its first js_event record")
    clock.sleep(5.0)
    assert src.poll(0.1).connected is False and src.fileno() is None  # never reopened
    src.close()


def test_a_device_answering_the_js_ioctls_is_a_joystick(monkeypatch):
    real_ioctl = reader.fcntl.ioctl

    def js_driver(fd, request, arg):
        if request == reader.JSIOCGVERSION:
            return b"\x00\x01\x02\x00"  # joydev answers JS_VERSION 0x020100
        return real_ioctl(fd, request, arg)

    monkeypatch.setattr(reader.fcntl, "ioctl", js_driver)
    src = open_joystick("/dev/null", FakeClock())
    assert src.kind == "device"
    src.close()


def test_a_pty_carrying_records_stays_accepted(pty_device):
    """A pseudo-terminal (socat forwarding a remote joystick's records) is a stream someone set up on purpose."""
    _master, path = pty_device
    src = open_joystick(path, FakeClock())
    assert src.kind == "device"
    src.close()


def test_a_fifo_opens_at_once_and_waits_for_its_writer(tmp_path):
    path = tmp_path / "js-fifo"
    os.mkfifo(path)
    src = open_joystick(str(path), FakeClock())
    assert src.poll(0.0).connected is False  # no writer yet: not connected, and no error
    src.close()


def test_a_device_replaced_by_something_else_is_not_reopened(pty_device, tmp_path, monkeypatch):
    _master, path = pty_device
    clock = FakeClock()
    src = JsDevice(path, clock)
    src.path = str(tmp_path)  # the node now names a directory

    def unplugged(fd, n):
        raise OSError(errno.ENODEV, "No such device")

    monkeypatch.setattr(reader.os, "read", unplugged)
    assert src.poll(0.1).connected is False
    monkeypatch.undo()
    clock.sleep(1.0)
    assert src.poll(0.1).connected is False
    assert "is a directory" in str(src.last_error)
    src.close()


@pytest.mark.parametrize("spec", ["", "script:", "raw:", "replay:"])
def test_a_joy_that_names_no_file_is_one_sentence(spec):
    with pytest.raises(JoystickError, match="names no file: give a device"):
        open_joystick(spec, FakeClock())
