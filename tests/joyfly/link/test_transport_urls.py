"""joyfly's connection URLs: checked before anything opens (ports, baud rates), serial links through pyserial, and
every failure one sentence (issue 10.3, 10.12)."""

from __future__ import annotations

import errno
import os
import tty
from pathlib import Path

import pytest

from joyfly.link.transport import Endpoint, TransportError, UrlError, _serial_problem, open_transport, parse_url


@pytest.mark.parametrize(("url", "endpoint"), [
    ("udp://:14540@127.0.0.1:14557", Endpoint("udp", ("0.0.0.0", 14540), ("127.0.0.1", 14557))),
    ("udp://127.0.0.1:0@localhost:65535", Endpoint("udp", ("127.0.0.1", 0), ("localhost", 65535))),
    ("udp://:14540@", Endpoint("udp", ("0.0.0.0", 14540), None)),
    ("udp://:14540@10.0.0.2/?ids=1,1", Endpoint("udp", ("0.0.0.0", 14540), ("10.0.0.2", 14555))),
    ("udpin:0.0.0.0:14540", Endpoint("udp", ("0.0.0.0", 14540))),
    ("udpout:127.0.0.1:14557", Endpoint("udp", ("0.0.0.0", 0), ("127.0.0.1", 14557))),
    ("tcp://127.0.0.1:5760", Endpoint("tcp", spec="tcp:127.0.0.1:5760")),
    ("tcp:localhost:1", Endpoint("tcp", spec="tcp:localhost:1")),
    ("tcpin:0.0.0.0:5760", Endpoint("tcp", spec="tcpin:0.0.0.0:5760")),
    ("/dev/ttyACM0", Endpoint("serial", spec="/dev/ttyACM0", baud=115200)),
    ("/dev/ttyUSB0:57600", Endpoint("serial", spec="/dev/ttyUSB0", baud=57600)),
    ("/dev/ttyUSB0,921600", Endpoint("serial", spec="/dev/ttyUSB0", baud=921600)),
    ("serial:///dev/ttyUSB0:57600", Endpoint("serial", spec="/dev/ttyUSB0", baud=57600)),
    ("COM3:57600", Endpoint("serial", spec="COM3", baud=57600)),
])
def test_good_urls_parse(url: str, endpoint: Endpoint) -> None:
    assert parse_url(url) == endpoint


@pytest.mark.parametrize(("url", "detail"), [
    ("udp://:99999@127.0.0.1:14557", "the listen port 99999 is out of range; use 0 to 65535 (0: any free port)"),
    ("udp://:14540@127.0.0.1:65536", "the vehicle port 65536 is out of range; use 1 to 65535"),
    ("udp://:14540@127.0.0.1:0", "the vehicle port 0 is out of range; use 1 to 65535"),
    ("udpout:127.0.0.1:99999", "the vehicle port 99999 is out of range; use 1 to 65535"),
    ("udpin:127.0.0.1:70000", "the listen port 70000 is out of range; use 0 to 65535 (0: any free port)"),
    ("udpin:127.0.0.1:-1", "the listen address '127.0.0.1:-1' is not HOST:PORT"),
    ("udp://@127.0.0.1:14557", "the listen address '' is not HOST:PORT"),
    ("tcp:127.0.0.1:0", "the TCP port 0 is out of range; use 1 to 65535"),
    ("tcp://127.0.0.1", "the TCP address '127.0.0.1' is not HOST:PORT"),
    ("/dev/ttyUSB0:9", "the baud rate 9 is out of range; use 50 to 4000000"),
    ("serial:///dev/ttyUSB0:99999999", "the baud rate 99999999 is out of range"),
    ("http://example.com", "use udp://:14540@127.0.0.1:14557 (MAVROS style)"),
])
def test_bad_urls_say_which_part_is_wrong(url: str, detail: str) -> None:
    with pytest.raises(UrlError) as err:
        parse_url(url)
    assert err.value.detail.startswith(detail)
    assert str(err.value) == f"Bad connection URL '{url}': {err.value.detail}."


def test_a_device_path_that_exists_is_the_device_even_with_a_colon(tmp_path: Path) -> None:
    device = tmp_path / "pci-0000:00:14.0-usb-0:1"  # like /dev/serial/by-path/ names
    device.touch()
    assert parse_url(f"serial://{device}") == Endpoint("serial", spec=str(device), baud=115200)


def test_a_serial_link_opens_through_pyserial_and_carries_bytes() -> None:
    """A pseudo-terminal stands in for the autopilot's serial port."""
    autopilot, port = os.openpty()
    tty.setraw(autopilot)
    transport = open_transport(f"{os.ttyname(port)}:57600")
    try:
        assert "57600 baud" in transport.description
        transport.write(b"\xfd\x09")
        assert os.read(autopilot, 100) == b"\xfd\x09"
        os.write(autopilot, b"\xfd\x01")
        assert transport.read(2.0) == b"\xfd\x01"
    finally:
        transport.close()
        os.close(autopilot)
        os.close(port)


@pytest.mark.parametrize(("url", "start"), [
    ("/dev/ttyUSB_joyfly_test_none", "No serial device /dev/ttyUSB_joyfly_test_none: plug the autopilot in"),
    ("/dev/null", "Cannot open the serial device /dev/null ("),
])
def test_a_serial_device_that_cannot_open_is_one_sentence(url: str, start: str) -> None:
    with pytest.raises(TransportError) as err:
        open_transport(url)
    assert str(err.value).startswith(start) and str(err.value).endswith(".")
    assert "\n" not in str(err.value)


def test_a_serial_device_without_permission_says_dialout(tmp_path: Path) -> None:
    if os.geteuid() == 0:
        pytest.skip("root may open anything")
    device = tmp_path / "ttyS_locked"
    device.touch(mode=0o000)
    with pytest.raises(TransportError, match=r"No permission to open .* add yourself to the dialout group"):
        open_transport(f"serial://{device}")


@pytest.mark.parametrize(("code", "words"), [
    (errno.EACCES, "No permission to open /dev/ttyX: add yourself to the dialout group"),
    (errno.EBUSY, "/dev/ttyX is busy: close the other program using it"),
    (errno.EIO, "Cannot open the serial device /dev/ttyX (Input/output error): check that it is the autopilot's"),
])
def test_serial_errors_say_what_to_do(code: int, words: str) -> None:
    text = _serial_problem("/dev/ttyX", OSError(code, os.strerror(code)))
    assert text.startswith(words) and text.endswith(".")


def test_an_unknown_vehicle_host_is_one_sentence() -> None:
    with pytest.raises(TransportError, match=r"^Unknown host 'nosuchhost.invalid' in --url: use an IP address"):
        open_transport("udpout:nosuchhost.invalid:14557")
