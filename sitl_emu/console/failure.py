"""`failure <component> <type> [-i instance | -m mask]` on the pxh> console and the MAVLink shell.

After src/systemcmds/failure/failure.cpp: refused unless SYS_FAILURE_EN is 1; the unit and type by name (the names of
sitl_emu/commander/failure_injection.py); one internal MAV_CMD_INJECT_FAILURE (param3 the instance, or NaN with the
mask in param4), then the ACK: an error line with the result if it is not ACCEPTED, or a timeout if none comes (the
failure injection manager did not start: SYS_FAILURE_EN was 0 at boot).
"""

from __future__ import annotations

import math
from typing import Any

from sitl_emu.commander.failure_injection import TYPES, UNITS
from sitl_emu.console.param import log_line
from sitl_emu.px4 import MavCmd, MavResult
from sitl_emu.types import VehicleCommand

NAN = math.nan
_USAGE_HEAD = """Usage: failure [arguments...]
   help          Show this help text
   gps|...       Specify component
   ok|off|...    Specify failure type
     [-i <val>]  sensor instance (0=all)
                 default: 0
     [-m <val>]  instance bitmask (bit i = instance i+1); overridden by -i
                 default: -1
"""


def usage() -> str:
    return (_USAGE_HEAD + "\nComponents:\n" + "".join(f"- {u}\n" for u in UNITS)
            + "\nFailure types:\n" + "".join(f"- {t}\n" for t in TYPES))


def _options(args: list[str]) -> tuple[list[str], int, int, bool] | None:
    """(positional words, instance, mask, instance given); None on an unknown option or a missing value."""
    words: list[str] = []
    instance, mask, instance_set = 0, -1, False
    it = iter(args)
    for arg in it:
        if arg in ("-i", "-m"):
            value = next(it, None)
            if value is None:
                return None
            if arg == "-i":
                instance, instance_set = _c_int(value) & 0xFF, True
            else:
                mask = _c_int(value, base=0)
        elif arg.startswith("-") and len(arg) > 1:
            return None
        else:
            words.append(arg)
    return words, instance, (-1 if instance_set else mask), instance_set


def _c_int(text: str, base: int = 10) -> int:
    """atoi / strtol: the leading number, 0 if none."""
    try:
        return int(text, base)
    except ValueError:
        return 0


def failure_command(vehicle: Any, args: list[str]) -> tuple[int, str]:
    if int(vehicle.params["SYS_FAILURE_EN"]) != 1:
        return 1, log_line("ERROR", "failure", "Failure injection disabled by SYS_FAILURE_EN param.")
    if args == ["help"]:
        return 0, usage()
    parsed = _options(args)
    if parsed is None:
        return 1, log_line("WARN", "failure", "Unknown option") + usage()
    words, instance, mask, _ = parsed
    if len(words) < 2:
        return 1, usage() + log_line("ERROR", "failure", "Not enough arguments.")
    unit, ftype = UNITS.get(words[0]), TYPES.get(words[1])
    if unit is None:
        return 1, log_line("ERROR", "failure", f"Component '{words[0]}' not found")
    if ftype is None:
        return 1, log_line("ERROR", "failure", f"Failure type '{words[1]}' not found")
    target = f"mask: 0x{mask:x}" if mask >= 0 else f"instance: {instance}"
    out = log_line("WARN", "failure", f"inject failure unit: {words[0]} ({unit}), type: {words[1]} ({ftype}), {target}")
    p3, p4 = (NAN, float(mask)) if mask >= 0 else (float(instance), NAN)
    params = (float(unit), float(ftype), p3, p4, NAN, NAN, NAN)
    ack = vehicle.handle_command(VehicleCommand(MavCmd.INJECT_FAILURE, params, source_system=vehicle.sysid,
                                                source_component=1, from_external=False))
    if ack is None:
        return 1, out + log_line("ERROR", "failure", "Timeout waiting for ack")
    if ack.result != MavResult.ACCEPTED:
        return 1, out + log_line("ERROR", "failure", f"Result: {ack.result}")
    return 0, out
