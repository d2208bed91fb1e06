"""What builds a link's messages, as the type checker sees it (its own module: mypyc cannot compile a protocol with
__getattr__, and context.py is compiled)."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:
    from pymavlink.dialects.v20.development import MAVLink_message

    from sitl_emu.mavlink.wire.fastpack import Packed


class MessageEncoder(Protocol):
    """Builds messages by name: `encoder.attitude_encode(...)`. The endpoint's is fastpack.ENCODER; pymavlink's
    MAVLink takes the same calls (the tests compare the two)."""

    def __getattr__(self, name: str) -> Callable[..., MAVLink_message | Packed]: ...  # context.OutMessage
