"""Failure injection as PX4 main does it: MAV_CMD_INJECT_FAILURE -> the failure table -> the parts that fail.

Sources: src/modules/mavlink/mavlink_receiver.cpp (INJECT_FAILURE: DENIED while SYS_FAILURE_EN is 0, else passed
on), src/modules/failure_injection_manager/ (FailureInjectionManager.cpp handleCommand: param1 unit, param2 type,
param3 instance (0 all) or, when NaN, param4 an instance mask; the ACK; the "Injected: ..." / "Cleared: ..." texts;
FailureTable.cpp isSupported and the mask rules; FailureStrings.hpp the names), failure_injection_manager_params.yaml
(SYS_FAILURE_EN, reboot required: the manager runs only if it was 1 at boot; PX4 SITL's rcS sets it to 1).

What fails here (the rest is accepted and tabled but changes nothing in SIH's emulation):
- gps off: no GPS: the estimator dead-reckons for EKF2_NOAID_TOUT, then has no horizontal position (vehicle/faults.py);
- motor off (instance n = motor n, 0 all): the control allocator stops that output (ControlAllocator.cpp
  motor_stop_mask from the failure detector's FailureInjector);
- battery off: remaining 0 and the emergency warning (FailureInjection.cpp process_battery).
PX4 main's table does not support rc_signal and mavlink_signal (UNSUPPORTED), so neither does this one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Final

from sitl_emu.px4 import MavResult

# failure_injection_s::FAILURE_UNIT_* and the `failure` command's names for them (FailureStrings.hpp unitName)
UNITS: Final = {"gyro": 0, "accel": 1, "mag": 2, "baro": 3, "gps": 4, "optical_flow": 5, "vio": 6,
                "distance_sensor": 7, "airspeed": 8, "battery": 100, "motor": 101, "servo": 102, "avoidance": 103,
                "rc_signal": 104, "mavlink_signal": 105, "esc": 106}
TYPES: Final = {"ok": 0, "off": 1, "stuck": 2, "garbage": 3, "wrong": 4, "slow": 5, "delayed": 6, "intermittent": 7}
UNIT_NAMES: Final = {v: k for k, v in UNITS.items()}
TYPE_NAMES: Final = {v: k for k, v in TYPES.items()}
GPS, BATTERY, MOTOR = UNITS["gps"], UNITS["battery"], UNITS["motor"]
OK, OFF = TYPES["ok"], TYPES["off"]
ALL_INSTANCES: Final = 0xFFFF
MAX_FAILURES: Final = 8  # failure_injection_s::MAX_FAILURES

_SENSOR_TYPES: Final = frozenset({OK, OFF, TYPES["stuck"]})
_SUPPORTED: Final[dict[int, frozenset[int]]] = {  # FailureTable::isSupported
    **{UNITS[u]: _SENSOR_TYPES for u in ("gyro", "accel", "mag", "baro", "distance_sensor")},
    **{UNITS[u]: _SENSOR_TYPES | {TYPES["wrong"]} for u in ("gps", "airspeed")},
    **{UNITS[u]: frozenset({OK, OFF}) for u in ("vio", "battery", "motor")},
    UNITS["esc"]: frozenset({OK, OFF, TYPES["wrong"]}),
}


def instance_to_mask(instance: int) -> int:
    """0 -> all instances, 1..16 -> that bit, beyond -> none."""
    if instance == 0:
        return ALL_INSTANCES
    return 1 << (instance - 1) if 0 < instance <= 16 else 0


def instance_phrase(mask: int) -> str:
    """FailureStrings.hpp instancePhrase: 'all instances', 'instances 1,2,4', 'no instances'."""
    if mask == 0:
        return "no instances"
    if mask == ALL_INSTANCES:
        return "all instances"
    return "instances " + ",".join(str(bit + 1) for bit in range(16) if mask & (1 << bit))


def _lround_u8(x: float) -> int:
    return int(math.copysign(math.floor(abs(x) + 0.5), x)) & 0xFF if math.isfinite(x) else 0


@dataclass
class FailureTable:
    """The active failures: (unit, type) -> instance mask; an instance is in one mode per unit."""

    entries: dict[tuple[int, int], int] = field(default_factory=dict)

    def inject(self, unit: int, ftype: int, mask: int) -> MavResult:
        if ftype not in _SUPPORTED.get(unit, frozenset()):
            return MavResult.UNSUPPORTED
        if mask == 0:
            return MavResult.ACCEPTED
        for key in [k for k in self.entries if k[0] == unit and k[1] != ftype]:  # clear from the other modes
            self.entries[key] &= ~mask
            if not self.entries[key]:
                del self.entries[key]
        if ftype == OK:
            self.entries.pop((unit, OK), None)
            return MavResult.ACCEPTED
        if (unit, ftype) not in self.entries and len(self.entries) >= MAX_FAILURES:
            return MavResult.TEMPORARILY_REJECTED
        self.entries[(unit, ftype)] = self.entries.get((unit, ftype), 0) | mask
        return MavResult.ACCEPTED

    def mask(self, unit: int, ftype: int = OFF) -> int:
        return self.entries.get((unit, ftype), 0)

    def failed(self, unit: int, instance: int = 1, ftype: int = OFF) -> bool:
        return bool(self.mask(unit, ftype) & (1 << (instance - 1)))


def command_target(p1: float, p2: float, p3: float, p4: float) -> tuple[int, int, int]:
    """(unit, type, instance mask) from INJECT_FAILURE's params (FailureInjectionManager::handleCommand)."""
    if math.isfinite(p3):
        mask = instance_to_mask(_lround_u8(p3))
    else:
        mask = int(math.copysign(math.floor(abs(p4) + 0.5), p4)) & 0xFFFF if math.isfinite(p4) else 0
    return _lround_u8(p1), _lround_u8(p2), mask


def announcement(unit: int, ftype: int, mask: int) -> str:
    """The manager's mavlink_log_warning after an accepted injection."""
    unit_name, phrase = UNIT_NAMES.get(unit, "unknown"), instance_phrase(mask)
    if ftype == OK:
        return f"Cleared: {unit_name}, {phrase}"
    return f"Injected: {unit_name} {TYPE_NAMES.get(ftype, 'unknown')}, {phrase}"
