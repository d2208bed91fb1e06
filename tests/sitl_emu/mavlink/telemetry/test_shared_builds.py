"""A message both links send in the same tick is built once; each link still frames it as its own.

telemetry/streams.py SharedBuilds: the API link (ONBOARD rates) and the GCS link (NORMAL rates) both stream
ATTITUDE_QUATERNION at 50 Hz, so every one of them is due on both links in the same tick. The builder must run once
per tick, the payloads must be the same and the frames each link's own (its sequence number, its signing link id);
a message that reads its link (LINK_NODE_STATUS) is built by each link.
"""

from __future__ import annotations

from typing import Any

import pytest
from support.fakes import HOME, Harness

from sitl_emu.mavlink.telemetry import streams as telemetry
from sitl_emu.mavlink.wire.signing import signature_block, signature_matches
from sitl_emu.vehicle.vehicle import Vehicle

ATTITUDE_QUATERNION = 31
KEY = bytes(range(32))


@pytest.fixture
def h():
    harness = Harness(Vehicle(home=HOME))
    yield harness
    harness.close()


def _counting(monkeypatch: pytest.MonkeyPatch, msg_id: int) -> list[int]:
    """Record the simulated time of every call of the stream's builder (the table entry is replaced, not the
    function: the compiled build runs the same test)."""
    calls: list[int] = []
    builder = telemetry.STREAMS[msg_id]

    def counted(ctx: Any, snap: Any) -> Any:
        calls.append(snap.time_us)
        return builder(ctx, snap)

    monkeypatch.setitem(telemetry.STREAMS, msg_id, counted)
    return calls


def test_a_message_both_links_send_in_a_tick_is_built_once_and_framed_by_each(h, monkeypatch):
    calls = _counting(monkeypatch, ATTITUDE_QUATERNION)
    h.run(1.0)
    api, gcs = h.api.of_type("ATTITUDE_QUATERNION"), h.gcs.of_type("ATTITUDE_QUATERNION")
    assert len(api) == len(gcs) >= 49
    assert len(calls) == len(set(calls)) == len(api)  # once per tick, not once per link
    assert [m.get_payload() for m in api] == [m.get_payload() for m in gcs]
    assert [m.get_seq() for m in api] != [m.get_seq() for m in gcs]  # each link's own sequence (more on the API)


def test_signed_each_link_signs_the_shared_message_with_its_own_link_id(h):
    h.node.signing.key = KEY
    h.run(0.2)
    for client, link_id in ((h.api, 1), (h.gcs, 0)):
        frames = [m.get_msgbuf() for m in client.of_type("ATTITUDE_QUATERNION")]
        assert len(frames) >= 9
        assert all(signature_matches(f, KEY) and signature_block(f)[0] == link_id for f in frames)


def test_link_node_status_is_each_links_own(h, monkeypatch):
    calls = _counting(monkeypatch, 8)
    h.run(2.0)
    api, gcs = h.api.of_type("UNKNOWN_8", None), h.gcs.of_type("UNKNOWN_8", None)  # (no source on unknowns)
    assert len(api) == len(gcs) == 2 and len(calls) == 4
    assert [m.get_msgbuf()[10:-2] for m in api] != [m.get_msgbuf()[10:-2] for m in gcs]  # each counts its own


def test_while_one_link_has_no_peer_the_other_keeps_nothing_for_it(h, monkeypatch):
    """A Sim's link builds nothing until a peer talks (mavlink/link.py), so the sharing is off: the API link builds
    and sends as alone; once both send again, they share again."""
    calls = _counting(monkeypatch, ATTITUDE_QUATERNION)
    gcs_remote = h.node.gcs.link.remote
    h.node.gcs.link.remote = None
    h.run(0.5)
    assert not h.node.shared.active
    assert len(calls) == len(h.api.of_type("ATTITUDE_QUATERNION")) >= 24 and not h.gcs.of_type("ATTITUDE_QUATERNION")
    h.node.gcs.link.remote = gcs_remote
    calls.clear()
    h.run(0.5)
    assert h.node.shared.active
    assert 24 <= len(calls) == len(h.gcs.of_type("ATTITUDE_QUATERNION")) < len(h.api.of_type("ATTITUDE_QUATERNION"))
