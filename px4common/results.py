"""MAV_RESULT: what a COMMAND_ACK says of a command (MAVLink common.xml), as PX4 answers and joyfly reads it."""

from __future__ import annotations

from enum import IntEnum


class MavResult(IntEnum):
    """MAV_RESULT, the COMMAND_ACK result."""

    ACCEPTED = 0
    TEMPORARILY_REJECTED = 1
    DENIED = 2
    UNSUPPORTED = 3
    FAILED = 4
    IN_PROGRESS = 5
    CANCELLED = 6


def result_name(result: int) -> str:
    """'ACCEPTED', 'DENIED'...; the number itself for a result MAVLink does not define."""
    return MavResult(result).name if result in MavResult._value2member_map_ else str(result)
