"""The contract between a link endpoint and the protocol handlers plugged into it.

An endpoint (one UDP link: API or GCS) owns a pymavlink encoder, the latched peer and the stream scheduler. For each
received message whose type a handler lists in MESSAGES, it calls handler.handle(msg, ctx); once per main-loop
iteration it calls handler.tick(ctx) so handlers can stream (parameter lists, shell output).
Handlers never touch sockets or clocks: they read ctx.now_us and call ctx.send().
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, ClassVar, Protocol

if TYPE_CHECKING:
    from pymavlink.dialects.v20.common import MAVLink, MAVLink_message

    from sitl_emu.vehicle import Vehicle


class LinkContext(Protocol):
    vehicle: Vehicle
    mav: MAVLink  # encoder with this vehicle's sysid/compid: ctx.mav.param_value_encode(...)
    link_name: str  # "api" or "gcs"
    sysid: int
    compid: int

    @property
    def now_us(self) -> int: ...

    def send(self, msg: MAVLink_message) -> None:
        """Send on this link, to its latched peer (or its initial remote)."""
        ...

    def broadcast(self, msg: MAVLink_message) -> None:
        """Send on every link of this vehicle (PX4 re-broadcasts changed parameters)."""
        ...


class Handler(Protocol):
    MESSAGES: ClassVar[tuple[str, ...]]  # pymavlink type names, e.g. ("PARAM_SET", "PARAM_REQUEST_LIST")
    # Optional: a handler whose tick() never sends may set `TICKS: ClassVar[bool] = False`; the endpoint then does
    # not call it (one call less per link and tick). Absent means True.

    def handle(self, msg: Any, ctx: LinkContext) -> None: ...

    def tick(self, ctx: LinkContext) -> None: ...
