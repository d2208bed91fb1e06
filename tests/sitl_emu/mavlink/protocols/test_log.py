"""The log protocol (PX4 src/modules/mavlink/mavlink_log_handler.cpp) over loopback UDP in lockstep.

Without logs (the emulator writes none yet) LOG_REQUEST_LIST gets PX4's empty answer, one LOG_ENTRY of zeros, so
MAVSDK's LogFiles reports "no log files" at once; with a DirectoryLogSource (PX4's log/<date>/<file> layout) the
entries and the data of each log stream as PX4 streams them.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from support.fakes import FakeVehicle, Harness

from sitl_emu.mavlink.endpoint import load_handler_classes
from sitl_emu.mavlink.protocols.log import (
    DATA_PER_TICK,
    LIST_ALL,
    LOG_DATA_LEN,
    DirectoryLogSource,
    LogProtocol,
    NoLogs,
)


def _harness(handler: type) -> Harness:
    h = Harness(FakeVehicle(), handler_classes=[handler])
    h.gcs.heartbeat()
    h.io()
    return h


@pytest.fixture()
def empty():
    h = _harness(LogProtocol)
    yield h
    h.close()


def _send(h: Harness, name: str, *args: int, target: tuple[int, int] = (1, 1)) -> None:
    h.gcs.send(getattr(h.gcs.mav, f"{name.lower()}_encode")(*target, *args))


def _entries(h: Harness) -> list[tuple[int, int, int, int, int]]:
    return [(m.id, m.num_logs, m.last_log_num, m.time_utc, m.size) for m in h.gcs.of_type("LOG_ENTRY")]


def test_every_link_answers_the_log_protocol_and_there_are_no_logs_by_default():
    assert LogProtocol in load_handler_classes()
    assert isinstance(LogProtocol.source, NoLogs) and LogProtocol.source.list_logs() == []


def test_request_list_without_logs_is_one_empty_log_entry(empty):
    _send(empty, "LOG_REQUEST_LIST", 0, LIST_ALL)
    empty.run(0.5)
    assert _entries(empty) == [(0, 0, 0, 0, 0)]
    entry = empty.gcs.of_type("LOG_ENTRY")[0]
    assert (entry.get_srcSystem(), entry.get_srcComponent()) == (1, 1)
    _send(empty, "LOG_REQUEST_LIST", 0, LIST_ALL)  # asked again: answered again
    empty.run(0.1)
    assert _entries(empty) == [(0, 0, 0, 0, 0)] * 2


def test_data_end_and_erase_without_logs_send_nothing(empty):
    _send(empty, "LOG_REQUEST_DATA", 0, 0, 1000)  # before any listing
    _send(empty, "LOG_REQUEST_LIST", 0, LIST_ALL)
    _send(empty, "LOG_REQUEST_DATA", 0, 0, 1000)
    _send(empty, "LOG_REQUEST_DATA", 7, 0, 0xFFFFFFFF)
    _send(empty, "LOG_REQUEST_END")
    _send(empty, "LOG_ERASE")
    empty.run(0.5)
    assert _entries(empty) == [(0, 0, 0, 0, 0)]
    assert empty.gcs.of_type("LOG_DATA") == []
    assert empty.node.gcs.stats.handler_errors == 0


def test_a_request_for_another_system_is_not_answered(empty):
    _send(empty, "LOG_REQUEST_LIST", 0, LIST_ALL, target=(2, 1))
    empty.run(0.2)
    assert _entries(empty) == []
    _send(empty, "LOG_REQUEST_LIST", 0, LIST_ALL, target=(0, 0))
    empty.run(0.2)
    assert _entries(empty) == [(0, 0, 0, 0, 0)]


@pytest.fixture()
def logs(tmp_path: Path):
    log_dir = tmp_path / "log"
    files = {
        "2026-01-01/10_00_00.ulg": os.urandom(9000),
        "2026-01-01/11_30_00.ulg": os.urandom(90 * 3),
        "2026-01-02/09_15_00.ulg": b"",
    }
    for i, (name, content) in enumerate(files.items()):
        path = log_dir / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(content)
        os.utime(path, (1_767_261_600 + i, 1_767_261_600 + i))
    (log_dir / "stray.txt").write_bytes(b"not in a session directory")
    h = _harness(LogProtocol.with_source(DirectoryLogSource(log_dir)))
    yield h, list(files.values()), log_dir
    h.close()


def _download(h: Harness, log_id: int, ofs: int, count: int) -> bytes:
    start = len(h.gcs.of_type("LOG_DATA"))
    _send(h, "LOG_REQUEST_DATA", log_id, ofs, count)
    h.run(0.5)
    out = bytearray()
    for m in h.gcs.of_type("LOG_DATA")[start:]:
        assert m.id == log_id and m.ofs == ofs + len(out) and m.count <= LOG_DATA_LEN
        out += bytes(m.data[:m.count])
    return bytes(out)


def test_logs_of_a_directory_are_listed_and_downloaded(logs):
    h, contents, _ = logs
    _send(h, "LOG_REQUEST_LIST", 0, LIST_ALL)
    h.run(0.2)
    sizes = [len(c) for c in contents]
    assert _entries(h) == [(i, 3, 3, 1_767_261_600 + i, sizes[i]) for i in range(3)]
    assert _download(h, 0, 0, 0xFFFFFFFF) == contents[0]
    assert _download(h, 1, 0, 1000) == contents[1]
    assert _download(h, 0, 500, 100) == contents[0][500:680]  # whole 90-byte packets until `count` is covered
    assert _download(h, 0, 9000, 10) == b""  # at the end: nothing
    assert _download(h, 2, 0, 10) == b""  # empty log
    assert _download(h, 3, 0, 10) == b""  # no such id


def test_list_from_a_start_id_and_end_stops_a_download(logs):
    h, contents, _ = logs
    _send(h, "LOG_REQUEST_LIST", 1, 2)
    h.run(0.2)
    assert [e[:3] for e in _entries(h)] == [(1, 3, 2), (2, 3, 2)]
    _send(h, "LOG_REQUEST_DATA", 0, 0, 0xFFFFFFFF)
    h.run(0.004)  # one tick: one tick's worth of LOG_DATA
    _send(h, "LOG_REQUEST_END")
    h.run(0.2)
    assert len(h.gcs.of_type("LOG_DATA")) == DATA_PER_TICK < len(contents[0]) // LOG_DATA_LEN


def test_erase_removes_every_log(logs):
    h, _, log_dir = logs
    _send(h, "LOG_REQUEST_LIST", 0, LIST_ALL)
    _send(h, "LOG_ERASE")
    h.run(0.2)
    assert not list(log_dir.glob("*/*"))
    assert (log_dir / "stray.txt").exists()
    _send(h, "LOG_REQUEST_LIST", 0, LIST_ALL)
    h.run(0.2)
    assert _entries(h)[-1] == (0, 0, 0, 0, 0)


def _listed(logs):
    h, contents, _ = logs
    _send(h, "LOG_REQUEST_LIST", 0, LIST_ALL)
    h.run(0.2)
    return h, contents


def _start_whole_download_of_log_0(h: Harness) -> int:
    """LOG_REQUEST_DATA for all of log 0, one tick of it streamed; the LOG_DATA count so far."""
    before = len(h.gcs.of_type("LOG_DATA"))
    _send(h, "LOG_REQUEST_DATA", 0, 0, 0xFFFFFFFF)
    h.run(0.004)
    sent = len(h.gcs.of_type("LOG_DATA"))
    assert sent - before == DATA_PER_TICK  # the download is under way, far from its end
    return sent


def test_an_offset_past_the_end_sends_nothing_and_stops_the_stream(logs):
    """mavlink_log_handler.cpp handle_log_request_data: ofs >= size_bytes -> Idle, nothing sent."""
    h, contents = _listed(logs)
    assert _download(h, 0, len(contents[0]) + 1, 10) == b""
    assert _download(h, 1, 10**9, 0xFFFFFFFF) == b""
    sent = _start_whole_download_of_log_0(h)
    _send(h, "LOG_REQUEST_DATA", 0, 10**6, 90)
    h.run(0.5)
    assert len(h.gcs.of_type("LOG_DATA")) == sent
    assert _download(h, 1, 0, 90 * 3) == contents[1]  # and the next request is answered


def test_a_huge_count_from_an_offset_wraps_as_px4s_uint32_sum_does(logs):
    """PX4 compares the offset with start_offset + byte_count, both uint32_t: past 0xFFFFFFFF it wraps."""
    h, contents = _listed(logs)
    assert _download(h, 0, 0, 0xFFFFFFFF) == contents[0]
    assert _download(h, 0, 900, 0xFFFFFFFF - 900) == contents[0][900:]  # sum 0xFFFFFFFF: to the end
    assert _download(h, 0, 900, 0xFFFFFFFF) == contents[0][900:990]  # wraps: one LOG_DATA
    assert _download(h, 0, 8990, 0xFFFFFFFF) == contents[0][8990:]  # one LOG_DATA, the file's last 10 bytes


def test_an_unknown_id_sends_nothing_and_stops_the_stream(logs):
    h, contents = _listed(logs)
    for unknown in (3, 0xFFFF):
        sent = _start_whole_download_of_log_0(h) if unknown == 3 else len(h.gcs.of_type("LOG_DATA"))
        _send(h, "LOG_REQUEST_DATA", unknown, 0, 0xFFFFFFFF)
        h.run(0.5)
        assert len(h.gcs.of_type("LOG_DATA")) == sent
    assert _download(h, 0, 0, 0xFFFFFFFF) == contents[0]


def test_a_client_that_stops_mid_download_then_asks_again_gets_the_new_request(logs):
    """No LOG_REQUEST_END: the next LOG_REQUEST_DATA replaces the piece being streamed (same log or another)."""
    h, contents = _listed(logs)
    _start_whole_download_of_log_0(h)
    assert _download(h, 0, 4500, 0xFFFFFFFF - 4500) == contents[0][4500:]  # nothing of the old piece after it
    _start_whole_download_of_log_0(h)
    assert _download(h, 1, 0, 1000) == contents[1]  # another log: only its data follows
    _start_whole_download_of_log_0(h)
    assert _download(h, 0, 0, 0xFFFFFFFF) == contents[0]  # from the start again: the whole file, once
