"""The events metadata a ground station decodes EVENTs with: the JSON PX4 builds from its sources (Tools/px4events:
jsonout.py for the events, src/lib/events/enums.json for the enums) and serves, xz-compressed, as the component
metadata of type MAV_COMP_METADATA_TYPE_EVENTS (mavlink/protocols/component_metadata.py).

Layout (libevents' format, version 2): components -> "1" (the autopilot) -> namespace "px4", enums (name -> type,
description, entries by value), event_groups -> group -> events by sub id (the lower 24 bits of the id) -> name,
message, arguments [{type, name}] with PX4's default argument names arg0, arg1, ... Built from catalogue.py, so it
lists exactly the events the emulator sends.
"""

from __future__ import annotations

from typing import Any

from sitl_emu.events import enums
from sitl_emu.events.catalogue import DEFINITIONS
from sitl_emu.events.library import AUTOPILOT_COMPONENT, sub_id

VERSION = 2


def _enum_json(e: enums.EventEnum) -> dict[str, Any]:
    return {"type": e.base_type, "description": e.description,
            "entries": {str(value): {"name": name, "description": text} for value, name, text in e.entries}}


def events_metadata() -> dict[str, Any]:
    groups: dict[str, dict[str, Any]] = {}
    for d in DEFINITIONS:
        event: dict[str, Any] = {"name": d.name, "message": d.message}
        if d.arguments:
            event["arguments"] = [{"type": t, "name": f"arg{i}"} for i, t in enumerate(d.arguments)]
        groups.setdefault(d.group, {"events": {}})["events"][str(sub_id(d.name))] = event
    component = {"namespace": enums.NAMESPACE, "enums": {e.name: _enum_json(e) for e in enums.ENUMS},
                 "event_groups": groups}
    return {"version": VERSION, "components": {str(AUTOPILOT_COMPONENT): component}}
