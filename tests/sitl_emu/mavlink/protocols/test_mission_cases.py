"""The mission protocol against the reference: the protocol cases of ../shared/reference/px4-mission/cases.json (a
copy in tests/reference/px4-mission), replayed in the order the probe ran them on one freshly booted vehicle, over
loopback UDP in lockstep simulated time.

The probe is a ground station (sysid 245 / compid 190, HEARTBEAT at 1 Hz) on the API link. Each case's exchange is
replayed message by message: what the probe sent ("tx") is sent, and every message PX4 answered ("rx") must come
back with the same fields, then nothing more; the STATUSTEXTs (text with PX4's tab, severity) must match. The
flight cases (flight1/2, the far waypoint's arm and start) belong to the slice that flies missions.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest
from support.fakes import Client, Harness

from sitl_emu.mavlink.protocols.mission import MissionProtocol
from sitl_emu.vehicle.vehicle import Vehicle

CASES: dict[str, Any] = json.loads((Path(__file__).parents[3] / "reference" / "px4-mission" / "cases.json").read_text())
PROTOCOL = ("MISSION_COUNT", "MISSION_REQUEST_INT", "MISSION_REQUEST", "MISSION_ITEM_INT", "MISSION_ITEM",
            "MISSION_ACK")
ORDER = ("download.empty", "upload.valid", "download.valid", "bad.rtl_global_frame_zero_xy", "bad.count_zero",
         "bad.count_zero.download", "bad.out_of_sequence", "bad.out_of_sequence.download", "bad.far_waypoint",
         "bad.far_waypoint_after_takeoff_item", "bad.unsupported_cmd", "bad.unsupported_cmd.download", "clear_all",
         "clear_all.download")


class Probe:
    """The reference's ground station on the API link: a 1 Hz HEARTBEAT, mission messages to target 1/1."""

    def __init__(self) -> None:
        self.h = Harness(Vehicle(), handler_classes=[MissionProtocol])
        self.h.api = self.client = Client(sysid=245, compid=190)
        self.client.target = ("127.0.0.1", self.h.node.api.link.port)
        self.h.node.api.link.remote = ("127.0.0.1", self.client.port)
        self._next_hb_us = 0

    def _tick(self) -> None:
        if self.h.vehicle.time_us >= self._next_hb_us:
            self.client.heartbeat()
            self._next_hb_us = self.h.vehicle.time_us + 1_000_000

    def run(self, seconds: float) -> None:
        self.h.run(seconds, self._tick)

    def protocol(self) -> list[Any]:
        return [m for m in self.client.received if m.get_type() in PROTOCOL]

    def texts(self) -> list[tuple[str, int]]:
        return [(m.text, m.severity) for m in self.client.of_type("STATUSTEXT")]

    def wait_protocol(self, n: int, timeout_s: float = 2.0) -> None:
        assert self.h.run_until(lambda: len(self.protocol()) >= n, timeout_s, self._tick), "no answer"

    def send(self, name: str, fields: dict[str, Any]) -> None:
        f = {k: (math.nan if v == "NaN" else v) for k, v in fields.items()}
        mav, kind = self.client.mav, f.get("mission_type", 0)
        if name == "MISSION_COUNT":
            msg = mav.mission_count_encode(1, 1, f["count"], kind)
        elif name == "MISSION_REQUEST_LIST":
            msg = mav.mission_request_list_encode(1, 1, kind)
        elif name == "MISSION_REQUEST_INT":
            msg = mav.mission_request_int_encode(1, 1, f["seq"], kind)
        elif name == "MISSION_ACK":
            msg = mav.mission_ack_encode(1, 1, f["type"], kind)
        elif name == "MISSION_CLEAR_ALL":
            msg = mav.mission_clear_all_encode(1, 1, kind)
        else:
            assert name == "MISSION_ITEM_INT"
            msg = mav.mission_item_int_encode(1, 1, f["seq"], f["frame"], f["command"], f["current"],
                                              f["autocontinue"], f["param1"], f["param2"], f["param3"], f["param4"],
                                              f["x"], f["y"], f["z"], kind)
        self.client.send(msg)

    def replay(self, exchange: list[Any]) -> tuple[list[Any], list[tuple[str, int]]]:
        """Send the tx messages, each once the rx messages before it have come; return the answers and texts."""
        start, texts_start = len(self.protocol()), len(self.texts())
        expected = 0
        for direction, name, fields in exchange:
            if direction == "tx":
                self.wait_protocol(start + expected)
                self.send(name, fields)
            else:
                expected += 1
        self.wait_protocol(start + expected)
        self.run(1.0)  # and nothing more
        return self.protocol()[start:], self.texts()[texts_start:]


def _same(expected: Any, got: Any) -> bool:
    if expected == "NaN":
        return isinstance(got, float) and math.isnan(got)
    return bool(got == pytest.approx(expected)) if isinstance(expected, float) else got == expected


def check_case(probe: Probe, case: dict[str, Any], exchange: list[Any] | None = None) -> None:
    exchange = case["exchange"] if exchange is None else exchange
    answers, texts = probe.replay(exchange)
    rx = [(name, fields) for direction, name, fields in exchange if direction == "rx"]
    assert [m.get_type() for m in answers] == [name for name, _ in rx]
    for msg, (name, fields) in zip(answers, rx, strict=True):
        wrong = {k: (v, getattr(msg, k)) for k, v in fields.items() if not _same(v, getattr(msg, k))}
        assert not wrong, f"{name}: (reference, ours) {wrong}"
        assert (msg.target_system, msg.target_component) == (245, 190)
    assert [t for t, _ in texts] == case["statustext"]
    assert [s for _, s in texts] == case["statustext_severity"]


@pytest.fixture(scope="module")
def probe() -> Any:
    p = Probe()
    p.run(2.5)  # the reference's ready wait
    yield p
    p.h.close()


@pytest.mark.parametrize("name", ORDER)
def test_case(probe: Probe, name: str) -> None:
    """Each case in the probe's order on one vehicle: later cases see what earlier ones stored (e.g. the download
    after a refused upload returns the plan stored before it)."""
    case = CASES[name]
    if name == "bad.out_of_sequence":
        _out_of_sequence(probe, case)
        return
    check_case(probe, case)
    if name == "upload.valid":
        current = probe.client.of_type("MISSION_CURRENT")
        probe.run(1.1)
        last = probe.client.of_type("MISSION_CURRENT")[-1]
        assert len(probe.client.of_type("MISSION_CURRENT")) > len(current)
        ref = CASES["upload.mission_current"]
        assert (last.seq, last.total, last.mission_state) == (ref["seq"], ref["total"], ref["mission_state"])


def _out_of_sequence(probe: Probe, case: dict[str, Any]) -> None:
    """Item 1 instead of 0: dropped, item 0 requested again every ~250 ms, and after 5 s without a message from the
    client "Mission sync timeout" (CRITICAL) and no MISSION_ACK; the stored plan is untouched (the next case)."""
    start, texts_start = len(probe.protocol()), len(probe.texts())
    t0 = probe.h.vehicle.time_us
    for direction, name, fields in case["exchange_start"]:
        if direction == "tx":
            probe.wait_protocol(start + (1 if name == "MISSION_ITEM_INT" else 0))
            probe.send(name, fields)
    assert probe.h.run_until(lambda: len(probe.texts()) > texts_start, 6.0, probe._tick)
    t_text_s = (probe.h.vehicle.time_us - t0) / 1e6
    probe.run(0.5)
    answers = probe.protocol()[start:]
    assert all(m.get_type() == "MISSION_REQUEST_INT" and m.seq == 0 for m in answers)
    re_requests = len(answers) - 1
    assert abs(re_requests - case["_info"]["re_requests"]) <= 1  # PX4: 19 in 5 s (every 250 ms + its loop)
    assert t_text_s == pytest.approx(case["t_sync_timeout_text_s"], abs=0.15)
    assert probe.texts()[texts_start:] == list(zip(case["statustext"], case["statustext_severity"], strict=True))


def test_two_links_upload_one_at_a_time_and_a_vanished_client_frees_the_vehicle() -> None:
    """Over UDP on both links: the GCS link's MISSION_COUNT while the API link uploads gets MAV_MISSION_ERROR; the
    API client then disappears mid-upload, PX4's 5 s timeout ends its transfer ("Mission sync timeout"), and the
    GCS link's upload goes through; the partial upload was never stored."""
    h = Harness(Vehicle(), handler_classes=[MissionProtocol])
    try:
        h.api.send(h.api.mav.mission_count_encode(1, 1, 3, 0))
        assert h.run_until(lambda: bool(h.api.of_type("MISSION_REQUEST_INT")), 1.0)
        h.gcs.send(h.gcs.mav.mission_count_encode(1, 1, 1, 0))
        assert h.run_until(lambda: bool(h.gcs.of_type("MISSION_ACK")), 1.0)
        assert h.gcs.of_type("MISSION_ACK")[-1].type == 1  # MAV_MISSION_ERROR: busy on another link
        assert h.run_until(lambda: any(e.text == "Mission sync timeout" for e in h.vehicle.events_after(0)), 6.0)
        assert len(h.api.of_type("MISSION_REQUEST_INT")) >= 15  # asked again every 250 ms meanwhile
        assert h.vehicle.mission_store().count(0) == 0
        h.gcs.send(h.gcs.mav.mission_count_encode(1, 1, 1, 0))
        assert h.run_until(lambda: bool(h.gcs.of_type("MISSION_REQUEST_INT")), 1.0)
        h.gcs.send(h.gcs.mav.mission_item_int_encode(1, 1, 0, 6, 16, 0, 1, 0, 0, 0, math.nan, 473977420, 85455940,
                                                     5.0, 0))
        assert h.run_until(lambda: len(h.gcs.of_type("MISSION_ACK")) == 2, 1.0)
        assert h.gcs.of_type("MISSION_ACK")[-1].type == 0 and h.vehicle.mission_store().count(0) == 1
    finally:
        h.close()
