"""Timed faults: a case lists (time_s, name) pairs, the scenario sends each as MAV_CMD_INJECT_FAILURE when it is due.

A name is `<unit>_<type>` with an optional `:<instance>` (0, the default, is every instance, as in PX4's
`failure <unit> <type> -i <instance>` command): units and types are MAVLink's FAILURE_UNIT and FAILURE_TYPE without
their prefixes (`gps_off`, `motor_off:1`, `battery_off`, `rc_signal_off`, `mavlink_signal_off`, `gps_ok` to
restore). PX4 obeys the command only with SYS_FAILURE_EN = 1 (src/modules/commander/Commander.cpp, the
VEHICLE_CMD_INJECT_FAILURE case), so a campaign with faults usually sets `params.SYS_FAILURE_EN = 1`.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from pymavlink.dialects.v20 import common as mavlink

from sitl_emu.campaign.errors import CaseError

__all__ = ["Fault", "FaultSchedule", "parse_fault"]


def _names(enum: str, prefixes: tuple[str, ...]) -> dict[str, int]:
    table: dict[str, int] = {}
    for value, entry in mavlink.enums[enum].items():
        if entry.name.endswith("_ENUM_END"):
            continue
        name = entry.name
        for prefix in prefixes:
            name = name.removeprefix(prefix)
        table[name.lower()] = value
    return table


UNITS = _names("FAILURE_UNIT", ("FAILURE_UNIT_SENSOR_", "FAILURE_UNIT_SYSTEM_"))
TYPES = _names("FAILURE_TYPE", ("FAILURE_TYPE_",))


@dataclass(frozen=True, order=True)
class Fault:
    """`name` at `t_s` simulated seconds after the case starts; `unit`, `type`, `instance` are the command's params."""

    t_s: float
    name: str
    unit: int = 0
    type: int = 0
    instance: int = 0

    def command_params(self) -> tuple[float, float, float, float, float, float, float]:
        """MAV_CMD_INJECT_FAILURE's seven params: failure unit, failure type, instance (0: all)."""
        return (float(self.unit), float(self.type), float(self.instance), 0.0, 0.0, 0.0, 0.0)


def parse_fault(t_s: object, name: object) -> Fault:
    """A Fault from its time and name, or CaseError naming the units and types there are."""
    if isinstance(t_s, bool) or not isinstance(t_s, (int, float)) or not t_s >= 0:
        raise CaseError(f"fault {name!r}: its time must be a number of seconds >= 0, not {t_s!r}.")
    text = str(name).strip().lower()
    base, _, instance = text.partition(":")
    unit, _, kind = base.rpartition("_")
    if unit not in UNITS or kind not in TYPES or not (instance == "" or instance.isdigit()):
        raise CaseError(f"unknown fault '{name}'; write UNIT_TYPE[:INSTANCE] with a unit of {', '.join(UNITS)} "
                        f"and a type of {', '.join(TYPES)} (for example gps_off or motor_off:1).")
    return Fault(float(t_s), text, UNITS[unit], TYPES[kind], int(instance or 0))


class FaultSchedule:
    """The case's faults in time order; `due(now_s)` hands out each one once, when its time has come."""

    def __init__(self, faults: Iterable[Fault]) -> None:
        self._pending = sorted(faults)

    def due(self, now_s: float) -> list[Fault]:
        ready = [f for f in self._pending if f.t_s <= now_s]
        self._pending = self._pending[len(ready):]
        return ready

    @property
    def pending(self) -> int:
        return len(self._pending)
