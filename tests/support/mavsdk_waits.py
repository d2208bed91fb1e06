"""Small awaitable helpers the MAVSDK conformance tests share: a call with a wall-clock bound, a poll until a value
is accepted, and a north/east offset in degrees (MAVSDK's timeouts run on the wall clock, so these are generous
bounds for a loaded machine, never timing asserts)."""

from __future__ import annotations

import asyncio
import math
import time
from collections.abc import Awaitable, Callable
from typing import Any

CALL_TIMEOUT_S = 20.0
EARTH_RADIUS_M = 6371000.0


async def call(awaitable: Awaitable[Any]) -> Any:
    return await asyncio.wait_for(awaitable, CALL_TIMEOUT_S)


async def wait(what: str, probe: Callable[[], Awaitable[Any]], accept: Callable[[Any], bool], timeout_s: float) -> Any:
    """Poll `probe()` every 0.1 s until `accept` takes its value; an AssertionError naming `what` after timeout_s."""
    deadline = time.monotonic() + timeout_s
    value: Any = None
    while time.monotonic() < deadline:
        value = await call(probe())
        if accept(value):
            return value
        await asyncio.sleep(0.1)
    raise AssertionError(f"timed out after {timeout_s} s waiting for {what}; last value: {value}")


def offset(lat: float, lon: float, north_m: float, east_m: float) -> tuple[float, float]:
    """The point north_m / east_m from (lat, lon), in degrees (a sphere: enough for tens of metres)."""
    return (lat + math.degrees(north_m / EARTH_RADIUS_M),
            lon + math.degrees(east_m / (EARTH_RADIUS_M * math.cos(math.radians(lat)))))
