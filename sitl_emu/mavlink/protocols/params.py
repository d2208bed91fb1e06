"""PX4's PARAM protocol on one link (src/modules/mavlink/mavlink_parameters.cpp, PX4 main; px4-behaviour.md section 10).

- PARAM_REQUEST_LIST: "_HASH_CHECK" first (index 65535, UINT32, not counted in param_count), then every used
  parameter in index order, up to 20 PARAM_VALUE per tick. A request during a running list restarts it without the hash.
- PARAM_REQUEST_READ: param_index >= 0 reads by used index; a negative index reads by name (PX4 compares the 16-char
  id), where "_HASH_CHECK" answers the hash and a known but unused parameter answers with index 65535 (PX4's
  param_get_used_index -1). Unknown name or index: PARAM_ERROR DOES_NOT_EXIST.
- PARAM_SET: the new value is echoed as PARAM_VALUE on the receiving link (also when unchanged). "_HASH_CHECK" stops
  the stream (if MAV_HASH_CHK_EN) and, as PX4 main, answers PARAM_ERROR READ_ONLY. Unknown name: DOES_NOT_EXIST;
  a type other than INT32/REAL32: TYPE_UNSUPPORTED; the other one of the two: TYPE_MISMATCH; read-only: READ_ONLY.
  PARAM_ERROR goes to the requester (PX4 main since commit f03131cfd3, 2025-10); PX4 <= v1.16 stayed silent.
- BE SAFER THAN PX4: a NaN, infinite or out-of-range value is refused (PX4 stores it as given): the value is kept, the
  refusal is reported as a critical text, and the requester gets PARAM_ERROR VALUE_OUT_OF_RANGE instead of the echo.
- Changed values are re-sent on every link (send_untransmitted): each link's instance notices a change of the
  registry in tick() and sends the changed used parameters on its own link, so changes made from another link or from
  the pxh> shell reach every client too.

INT32 values travel bytewise in the float field (MAV_PROTO capability PARAM_ENCODE_BYTEWISE): the int32's four bytes
are reinterpreted as a float32. Limitation: CPython turns signalling-NaN float32 bit patterns into quiet NaNs, so the
INT32 values 2139095041..2143289343 and -8388607..-4194305 cannot travel bytewise; no PX4 default uses them.
"""

from __future__ import annotations

import logging
import math
import struct
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, ClassVar, cast

from pymavlink.dialects.v20 import development as _dialect

from sitl_emu.mavlink.wire.fastpack import ENCODER, Packed
from sitl_emu.params.registry import ParamError, ParamRegistry, ParamType
from sitl_emu.px4 import Severity

if TYPE_CHECKING:
    from typing import TypeAlias

    from pymavlink.dialects.v20 import development as dialect
    from pymavlink.dialects.v20.development import MAVLink_message

    from sitl_emu.mavlink.context import LinkContext

    _ParamMessage: TypeAlias = (dialect.MAVLink_param_request_list_message | dialect.MAVLink_param_request_read_message
                                | dialect.MAVLink_param_set_message)

log = logging.getLogger(__name__)

HASH_CHECK_NAME = "_HASH_CHECK"
HASH_CHECK_INDEX = 65535  # param_index -1 as uint16
UNUSED_INDEX = 65535  # PARAM_VALUE.param_index of a parameter that is not used (PX4 sends -1)
MAV_PARAM_TYPE_UINT32 = 5
MAV_PARAM_TYPE_INT32 = 6
MAV_PARAM_TYPE_REAL32 = 9
PARAMS_PER_TICK = 20  # mavlink_parameters.cpp: up to 20 PARAM_VALUE per main-loop iteration on UDP links

# MAV_PARAM_ERROR (common.xml; pymavlink 2.4.50 names only some of them)
PARAM_ERROR_DOES_NOT_EXIST = 1
PARAM_ERROR_VALUE_OUT_OF_RANGE = 2
PARAM_ERROR_READ_ONLY = 5
PARAM_ERROR_TYPE_UNSUPPORTED = 6
PARAM_ERROR_TYPE_MISMATCH = 7

_TYPE_CODES = {ParamType.INT32: MAV_PARAM_TYPE_INT32, ParamType.REAL32: MAV_PARAM_TYPE_REAL32}
_HAS_PARAM_ERROR = hasattr(_dialect, "MAVLink_param_error_message")  # an old pymavlink may lack it


def int32_to_float_bits(value: int) -> float:
    """The float whose four bytes are the int32 `value` (PX4's bytewise encoding)."""
    return float(struct.unpack("<f", struct.pack("<i", int(value)))[0])


def float_bits_to_int32(value: float) -> int:
    return int(struct.unpack("<i", struct.pack("<f", value))[0])


def uint32_to_float_bits(value: int) -> float:
    return float(struct.unpack("<f", struct.pack("<I", int(value) & 0xFFFFFFFF))[0])


def _param_id(msg: dialect.MAVLink_param_request_read_message | dialect.MAVLink_param_set_message) -> str:
    raw: str | bytes = msg.param_id  # str in newer pymavlink releases, bytes in older ones
    if isinstance(raw, bytes):
        raw = raw.decode("ascii", errors="replace")
    return raw.split("\x00", 1)[0]


class ParamProtocol:
    """One instance per link; see the module docstring."""

    MESSAGES: ClassVar[tuple[str, ...]] = ("PARAM_REQUEST_LIST", "PARAM_REQUEST_READ", "PARAM_SET")
    WATCHES_VEHICLE: ClassVar[bool] = True  # tick() sends the values changed (context.vehicle_news)

    def __init__(self) -> None:
        self._next_index: int | None = None  # next index to stream, None when not streaming
        self._send_hash = False
        self._seen_version: int | None = None
        self._seen_values: dict[str, float] = {}
        # message type -> its handler, which takes that type's message class (the one place a message is narrowed)
        self._table: dict[str, Callable[[Any, LinkContext], None]] = {
            "PARAM_REQUEST_LIST": self._start_list,
            "PARAM_REQUEST_READ": self._handle_read,
            "PARAM_SET": self._handle_set,
        }

    # --- receive -----------------------------------------------------------------------------------------------
    def handle(self, msg: MAVLink_message, ctx: LinkContext) -> None:
        handler = self._table.get(msg.get_type())
        if handler is not None and self._addressed_to_us(cast("_ParamMessage", msg), ctx):  # a type of the table
            handler(msg, ctx)

    @staticmethod
    def _addressed_to_us(msg: _ParamMessage, ctx: LinkContext) -> bool:
        # PX4 accepts only its own sysid exactly (0 is not a broadcast here) and its compid or 0 (section 10.1).
        return msg.target_system == ctx.sysid and msg.target_component in (ctx.compid, 0)

    def _start_list(self, msg: dialect.MAVLink_param_request_list_message, ctx: LinkContext) -> None:
        # A request during a running list restarts it from index 0 without the hash (section 10.1).
        self._send_hash = self._next_index is None
        self._next_index = 0

    def _handle_read(self, msg: dialect.MAVLink_param_request_read_message, ctx: LinkContext) -> None:
        registry: ParamRegistry = ctx.vehicle.params
        if msg.param_index >= 0:
            if msg.param_index < len(registry):
                ctx.send(self._value_msg(ctx, registry.name_at(msg.param_index)))
            else:
                _error(ctx, msg, "", msg.param_index, PARAM_ERROR_DOES_NOT_EXIST)
            return
        name = _param_id(msg)
        if name == HASH_CHECK_NAME:
            ctx.send(self._hash_msg(ctx))
        elif name in registry:
            ctx.send(self._value_msg(ctx, name))
        else:
            _error(ctx, msg, name, -1, PARAM_ERROR_DOES_NOT_EXIST)

    def _handle_set(self, msg: dialect.MAVLink_param_set_message, ctx: LinkContext) -> None:
        registry: ParamRegistry = ctx.vehicle.params
        name = _param_id(msg)
        if name == HASH_CHECK_NAME:
            if self._hash_check_enabled(registry):
                self._next_index = None  # the client's cache is current: stop streaming
            _error(ctx, msg, name, -1, PARAM_ERROR_READ_ONLY)
            return
        problem = _set_problem(registry, name, msg.param_type)
        if problem:
            _error(ctx, msg, name, -1, problem)
            return
        if registry.definition(name).type is ParamType.INT32:
            value: float = float_bits_to_int32(msg.param_value)
        else:
            value = msg.param_value
        try:
            registry.set(name, value)
        except ParamError as err:
            # BE SAFER THAN PX4 (module docstring): keep the value, say why, and tell the requester it was refused.
            ctx.vehicle.report(Severity.CRITICAL, "param", str(err), is_event=False)
            _error(ctx, msg, name, -1, PARAM_ERROR_VALUE_OUT_OF_RANGE)
            return
        ctx.send(self._value_msg(ctx, name))

    @staticmethod
    def _hash_check_enabled(registry: ParamRegistry) -> bool:
        return "MAV_HASH_CHK_EN" not in registry or int(registry.get("MAV_HASH_CHK_EN")) == 1

    # --- transmit ----------------------------------------------------------------------------------------------
    def tick(self, ctx: LinkContext) -> bool:
        """Changed values, then the list being streamed; False when neither is left (idle until news or a
        request)."""
        if self._next_index is None and self._seen_version == ctx.vehicle.params.version:
            return False
        self._send_changes(ctx)
        self._stream(ctx)
        return self._next_index is not None

    def _stream(self, ctx: LinkContext) -> None:
        if self._next_index is None:
            return
        registry: ParamRegistry = ctx.vehicle.params
        budget = PARAMS_PER_TICK
        if self._send_hash:
            ctx.send(self._hash_msg(ctx))
            self._send_hash = False
            budget -= 1
        index = self._next_index
        count = len(registry)
        while budget > 0 and index < count:
            ctx.send(self._value_msg(ctx, registry.name_at(index)))
            index += 1
            budget -= 1
        self._next_index = index if index < count else None

    def _send_changes(self, ctx: LinkContext) -> None:
        """Re-send every used parameter whose value changed since the last tick (PX4's send_untransmitted)."""
        registry: ParamRegistry = ctx.vehicle.params
        if self._seen_version == registry.version:
            return
        values = registry.values()
        if self._seen_version is not None:
            for name, value in values.items():
                old = self._seen_values.get(name)
                if (old is None or not _same(old, value)) and registry.is_used(name):
                    ctx.send(self._value_msg(ctx, name))
        self._seen_version = registry.version
        self._seen_values = values

    @staticmethod
    def _value_msg(ctx: LinkContext, name: str) -> Packed:
        registry: ParamRegistry = ctx.vehicle.params
        definition = registry.definition(name)
        value = registry.get(name)
        if definition.type is ParamType.INT32:
            wire = int32_to_float_bits(int(value))
        else:
            wire = float(value)
        index = registry.index_of(name)
        return ENCODER.param_value_encode(name.encode("ascii"), wire, _TYPE_CODES[definition.type], len(registry),
                                          index if index >= 0 else UNUSED_INDEX)

    @staticmethod
    def _hash_msg(ctx: LinkContext) -> Packed:
        registry: ParamRegistry = ctx.vehicle.params
        wire = uint32_to_float_bits(registry.hash_check())
        return ENCODER.param_value_encode(HASH_CHECK_NAME.encode("ascii"), wire, MAV_PARAM_TYPE_UINT32, len(registry),
                                          HASH_CHECK_INDEX)


def _set_problem(registry: ParamRegistry, name: str, type_code: int) -> int:
    """The MAV_PARAM_ERROR a PARAM_SET of `name` with `type_code` gets before its value is looked at; 0 if none."""
    if name not in registry:
        return PARAM_ERROR_DOES_NOT_EXIST
    if type_code not in _TYPE_CODES.values():
        return PARAM_ERROR_TYPE_UNSUPPORTED
    definition = registry.definition(name)
    if type_code != _TYPE_CODES[definition.type]:
        return PARAM_ERROR_TYPE_MISMATCH
    return PARAM_ERROR_READ_ONLY if definition.read_only else 0


def _error(ctx: LinkContext, request: MAVLink_message, name: str, index: int, code: int) -> None:
    """PARAM_ERROR (#345) to the component that asked (none if pymavlink's dialect lacks it: PX4 v1.16's silence)."""
    log.debug("%s %r (index %d): PARAM_ERROR %d", request.get_type(), name, index, code)
    if not _HAS_PARAM_ERROR:
        return
    ctx.send(ENCODER.param_error_encode(request.get_srcSystem(), request.get_srcComponent(),
                                        name.encode("ascii", errors="replace"), index, code))


def _same(a: float, b: float) -> bool:
    return a == b or (isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b))
