"""The events metadata a ground station decodes EVENTs with: the JSON PX4 builds from its sources (Tools/px4events:
jsonout.py for the events, src/lib/events/enums.json for the enums) and serves, xz-compressed, as the component
metadata of type MAV_COMP_METADATA_TYPE_EVENTS (mavlink/protocols/component_metadata.py).

Layout (libevents' format, version 2): components -> "1" (the autopilot) -> namespace "px4", enums (name -> type,
description, is_bitfield, entries by value), event_groups -> group -> events by sub id (the lower 24 bits of the id)
-> name, message, type (the report's summaries), arguments [{type, name}] with PX4's default argument names arg0,
arg1, ... Built from catalogue.py, so it lists exactly the events the emulator sends. enums.json also declares the
protocol the autopilot speaks ("supported_protocols": the health and arming check report, which QGroundControl looks
for before it reads the report) and "navigation_mode_groups" (a group's bit number -> the custom modes in it, here
each nav_state's own custom mode), by which a client finds the can_arm bit of the mode it sees in the HEARTBEAT.
"""

from __future__ import annotations

from typing import Any

from sitl_emu.events import enums
from sitl_emu.events.catalogue import DEFINITIONS
from sitl_emu.events.library import AUTOPILOT_COMPONENT, sub_id
from sitl_emu.px4 import NavState, custom_mode

VERSION = 2
SUPPORTED_PROTOCOLS = ["health_and_arming_check"]


def _enum_json(e: enums.EventEnum) -> dict[str, Any]:
    out: dict[str, Any] = {"type": e.base_type, "description": e.description}
    if e.is_bitfield:
        out["is_bitfield"] = True
    out["entries"] = {str(value): {"name": name, "description": text} for value, name, text in e.entries}
    return out


def _mode_groups() -> dict[str, Any]:
    """Each navigation_mode_group_t entry (bit n) holds nav_state n's custom mode."""
    bits = [value.bit_length() - 1 for value, name, _ in enums.NAVIGATION_MODE_GROUP.entries
            if not name.startswith("external")]
    return {"groups": {str(bit): [custom_mode(NavState(bit))] for bit in bits}}


def events_metadata() -> dict[str, Any]:
    groups: dict[str, dict[str, Any]] = {}
    for d in DEFINITIONS:
        event: dict[str, Any] = {"name": d.name, "message": d.message}
        if d.type:
            event["type"] = d.type
        if d.arguments:
            event["arguments"] = [{"type": t, "name": f"arg{i}"} for i, t in enumerate(d.arguments)]
        groups.setdefault(d.group, {"events": {}})["events"][str(sub_id(d.name))] = event
    component = {"namespace": enums.NAMESPACE, "enums": {e.name: _enum_json(e) for e in enums.ENUMS},
                 "event_groups": groups, "navigation_mode_groups": _mode_groups(),
                 "supported_protocols": SUPPORTED_PROTOCOLS}
    return {"version": VERSION, "components": {str(AUTOPILOT_COMPONENT): component}}
