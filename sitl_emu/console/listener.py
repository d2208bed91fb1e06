"""`listener <topic> [-n N]`: PX4's uORB topic printer, for the topics sitl_emu models, read from the vehicle snapshot.

What it prints follows PX4 (v1.14+):
- src/systemcmds/topic_listener/listener_main.cpp: one message is "\\nTOPIC: <name>\\n"; with -n N each of the N
  messages is "\\nTOPIC: <name> instance 0 #<i>\\n"; an unknown name gets "Topic <name> did not match any known
  topics" and the command fails with -1; -i other than 0 gets "never published".
- platforms/common/uORB/uORB.cpp orb_print_message_internal(): the topic name again after one space, then one
  "    <field>: <value>" line per field in the message's (size-sorted) field order: float "%.5f", double "%.6f",
  bool True/False, integers in decimal; `timestamp` gets " (<now - timestamp> seconds ago)" ("%.6f") and
  `timestamp_sample` " (<timestamp - timestamp_sample> us before timestamp)".
Field names and their order are PX4's (reference/px4-ulog-topics.txt). sitl_emu prints the fields it models; the
others (variances, reset counters, terrain estimates, ...) are left out rather than filled with made-up values.

A message is "published" when PX4 would publish one, on simulated time: vehicle_local_position at the 125 Hz a PX4
SITL log shows for it (px4-ulog-topics.txt: 124.9 Hz), battery_status at the battery simulator's 100 Hz
(src/modules/simulation/battery_simulator/BatterySimulator.hpp BATTERY_SIMLATOR_SAMPLE_FREQUENCY_HZ) and
vehicle_status at 2 Hz or at once when it changes (Commander.cpp: "publish states ... at 2 Hz or immediately when
changed"). Each message shows the snapshot of the moment it is printed, stamped with that snapshot's time.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Hashable
from dataclasses import dataclass
from typing import Any

from sitl_emu.types import VehicleSnapshot

Field = tuple[str, str, Any]  # (PX4 field name, C type, value)

MAX_MESSAGES = 100  # listener usage: -n 0..100
ARMING_STATE_DISARMED = 1  # msg/VehicleStatus.msg
ARMING_STATE_ARMED = 2
VEHICLE_TYPE_ROTARY_WING = 1  # msg/VehicleStatus.msg VEHICLE_TYPE_*
MAV_TYPE_QUADROTOR = 2  # vehicle_status.system_type is the MAV_TYPE
AUTOPILOT_COMPID = 1
BATTERY_CELLS = 4  # BAT1_N_CELLS in PX4 SITL (also the cells of sitl_emu's BATTERY_STATUS)
BATTERY_ID = 1  # BatterySimulator's Battery(1, ...): ids are 1-based

USAGE = """Usage: listener <command> [arguments...]
     <topic_name> uORB topic name
     [-i <val>]  Topic instance
                 default: 0
     [-n <val>]  Number of messages
                 default: 1
     [-r <val>]  Subscription rate (unlimited if 0)
                 default: 0
 Topics sitl_emu publishes: {topics}
"""


@dataclass(frozen=True, slots=True)
class Topic:
    name: str
    period_us: int  # PX4's publication period: a new message for `listener -n` at least this often
    fields: Callable[[Any, VehicleSnapshot], list[Field]]
    state: Callable[[VehicleSnapshot], Hashable] | None = None  # a change of it is published at once


def _local_position(vehicle: Any, snap: VehicleSnapshot) -> list[Field]:
    x, y, z = snap.pos_ned_m
    vx, vy, vz = snap.vel_ned_m_s
    ax, ay, az = snap.acc_ned_m_s2
    valid = snap.position_valid
    return [
        ("timestamp", "uint64_t", snap.time_us), ("timestamp_sample", "uint64_t", snap.time_us),
        ("ref_lat", "double", snap.ref_lat_deg), ("ref_lon", "double", snap.ref_lon_deg),
        ("x", "float", x), ("y", "float", y), ("z", "float", z),
        ("vx", "float", vx), ("vy", "float", vy), ("vz", "float", vz), ("z_deriv", "float", vz),
        ("ax", "float", ax), ("ay", "float", ay), ("az", "float", az),
        ("heading", "float", snap.euler_rad[2]), ("ref_alt", "float", snap.ref_alt_amsl_m),
        ("xy_valid", "bool", valid), ("z_valid", "bool", valid), ("v_xy_valid", "bool", valid),
        ("v_z_valid", "bool", valid), ("xy_global", "bool", valid), ("z_global", "bool", valid),
    ]


def _vehicle_status(vehicle: Any, snap: VehicleSnapshot) -> list[Field]:
    return [
        ("timestamp", "uint64_t", snap.time_us),
        ("arming_state", "uint8_t", ARMING_STATE_ARMED if snap.armed else ARMING_STATE_DISARMED),
        ("nav_state_user_intention", "uint8_t", int(snap.user_intended_nav_state)),
        ("nav_state", "uint8_t", int(snap.nav_state)),
        ("vehicle_type", "uint8_t", VEHICLE_TYPE_ROTARY_WING),
        ("failsafe", "bool", snap.failsafe),
        ("system_type", "uint8_t", MAV_TYPE_QUADROTOR),
        ("system_id", "uint8_t", int(vehicle.sysid)),
        ("component_id", "uint8_t", AUTOPILOT_COMPID),
        ("is_vtol", "bool", False),
        ("pre_flight_checks_pass", "bool", snap.pre_flight_checks_pass),
    ]


def _status_state(snap: VehicleSnapshot) -> Hashable:
    return snap.armed, snap.nav_state, snap.user_intended_nav_state, snap.failsafe, snap.pre_flight_checks_pass


def _battery_status(vehicle: Any, snap: VehicleSnapshot) -> list[Field]:
    return [
        ("timestamp", "uint64_t", snap.time_us),
        ("voltage_v", "float", snap.battery_voltage_v),
        ("remaining", "float", snap.battery_remaining),
        ("connected", "bool", True),
        ("cell_count", "uint8_t", BATTERY_CELLS),
        ("id", "uint8_t", BATTERY_ID),
    ]


TOPICS: dict[str, Topic] = {t.name: t for t in (
    Topic("battery_status", 10_000, _battery_status),
    Topic("vehicle_local_position", 8_000, _local_position),
    Topic("vehicle_status", 500_000, _vehicle_status, _status_state),
)}


def usage() -> str:
    return USAGE.format(topics=", ".join(TOPICS))


def unknown_topic(name: str) -> str:
    """PX4's answer, then which topics sitl_emu has (PX4 knows many more than the emulator publishes)."""
    return f"Topic {name} did not match any known topics\n" + f"sitl_emu publishes: {', '.join(TOPICS)}\n"


def format_message(topic: Topic, vehicle: Any, header: str) -> str:
    """`header` ("TOPIC: name" or "TOPIC: name instance 0 #i"), then the fields as orb_print_message_internal."""
    now_us = int(vehicle.time_us)
    lines = [f"\n{header}\n", f" {topic.name}\n"]
    timestamp = 0
    for name, ctype, value in topic.fields(vehicle, vehicle.snapshot()):
        text = _format_value(ctype, value)
        if name == "timestamp":
            timestamp = int(value)
            if timestamp != 0:
                text += f" ({(now_us - timestamp) / 1e6:.6f} seconds ago)"
        elif name == "timestamp_sample" and timestamp != 0 and value != 0:
            text += f" ({timestamp - int(value)} us before timestamp)"
        lines.append(f"    {name}: {text}\n")
    return "".join(lines)


def _format_value(ctype: str, value: Any) -> str:
    if ctype == "bool":
        return "True" if value else "False"
    if ctype == "float":
        return _c_float(float(value), 5)
    if ctype == "double":
        return _c_float(float(value), 6)
    return str(int(value))


def _c_float(value: float, digits: int) -> str:
    """printf("%.Nf"): NaN prints as "nan" and infinities as "inf"/"-inf", as glibc does."""
    if math.isnan(value):
        return "nan"
    return f"{value:.{digits}f}"


class ListenerJob:
    """`listener <topic> -n N`: N messages, each printed when PX4 would publish the next one (on simulated time)."""

    def __init__(self, topic: Topic, vehicle: Any, count: int, min_interval_us: int = 0) -> None:
        self.topic = topic
        self.vehicle = vehicle
        self.count = count
        self.printed = 0
        self._period_us = max(topic.period_us, min_interval_us)
        self._last_us = 0
        self._last_state: Hashable = None

    @property
    def done(self) -> bool:
        return self.printed >= self.count

    def poll(self) -> str:
        """The next message if one is due (the first at once), else ""."""
        if self.done or not self._due():
            return ""
        self.printed += 1
        self._last_us = int(self.vehicle.time_us)
        if self.topic.state is not None:
            self._last_state = self.topic.state(self.vehicle.snapshot())
        return format_message(self.topic, self.vehicle, f"TOPIC: {self.topic.name} instance 0 #{self.printed}")

    def _due(self) -> bool:
        if self.printed == 0:
            return True
        now_us = int(self.vehicle.time_us)
        if now_us < self._last_us or now_us >= self._last_us + self._period_us:  # (time going back: a reboot)
            return True
        state = self.topic.state
        return state is not None and state(self.vehicle.snapshot()) != self._last_state
