"""What builds a link's messages, as the type checker sees it (its own module: mypyc cannot compile a protocol with
__getattr__, and context.py is compiled)."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:
    from sitl_emu.mavlink.wire.fastpack import Packed


class MessageEncoder(Protocol):
    """Builds messages by name: `encoder.attitude_encode(...)`, the calls of pymavlink's MAVLink. The one
    implementation is fastpack.ENCODER."""

    def __getattr__(self, name: str) -> Callable[..., Packed]: ...  # context.OutMessage
