"""What the MAVSDK conformance tests share: the server's speed (the `mavsdk_port` fixture in tests/conftest.py), a call
with a wall-clock bound, a poll until a value is accepted, a north/east offset in degrees, and a Session that records
every call and its outcome (MAVSDK's timeouts run on the wall clock, so these are generous bounds for a loaded
machine, never timing asserts)."""

from __future__ import annotations

import asyncio
import math
import time
from collections.abc import Awaitable, Callable
from typing import Any

from sitl_emu.geo import EARTH_RADIUS_M

MAVSDK_SPEED = 4.0  # the server's simulated seconds per wall second: MAVSDK retries commands after 0.5 s of wall time
CALL_TIMEOUT_S = 20.0
SESSION_CALL_TIMEOUT_S = 15.0  # no single call in a recorded Session may hang the test


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


class Session:
    """Runs MAVSDK calls with a timeout each and records every call and its outcome (`table()`, printed by the tests
    at the end: run with -s to see it)."""

    def __init__(self) -> None:
        self.calls: list[tuple[str, str]] = []

    async def call(self, name: str, awaitable: Awaitable[Any], timeout_s: float = SESSION_CALL_TIMEOUT_S) -> Any:
        try:
            result = await asyncio.wait_for(awaitable, timeout_s)
        except Exception as err:
            self.calls.append((name, f"FAILED: {type(err).__name__}: {err}"))
            raise
        self.calls.append((name, "ok" if result is None else f"ok -> {_short(result)}"))
        return result

    async def wait_for(self, what: str, probe: Callable[[], Awaitable[Any]], accept: Callable[[Any], bool],
                       timeout_s: float) -> Any:
        """Poll `probe` until `accept(value)`; fail with the last value seen."""
        deadline = time.monotonic() + timeout_s
        value: Any = None
        while time.monotonic() < deadline:
            value = await asyncio.wait_for(probe(), SESSION_CALL_TIMEOUT_S)
            if accept(value):
                self.calls.append((f"wait: {what}", f"ok -> {_short(value)}"))
                return value
            await asyncio.sleep(0.1)
        self.calls.append((f"wait: {what}", f"TIMED OUT, last {_short(value)}"))
        raise AssertionError(f"timed out after {timeout_s} s waiting for {what}; last value: {value}")

    def table(self) -> str:
        return "\n".join(f"  {name:<48} {outcome}" for name, outcome in self.calls)


def _short(value: Any) -> str:
    text = str(value).replace("\n", " ")
    return text if len(text) <= 110 else text[:107] + "..."


async def connect(mavsdk: Any, port: int, s: Session) -> Any:
    """The autopilot MAVSDK hears on udpin PORT, once its health is all good."""
    from mavsdk.asyncio.plugins.telemetry import TelemetryAsync

    await s.call("Mavsdk.add_any_connection(udpin)", mavsdk.add_any_connection(f"udpin://0.0.0.0:{port}"))
    system = await s.call("Mavsdk.first_autopilot", mavsdk.first_autopilot(timeout_s=20.0), timeout_s=25.0)
    assert system is not None, "MAVSDK found no autopilot"
    await s.wait_for("health_all_ok", TelemetryAsync(system).health_all_ok, bool, timeout_s=30)
    return system
