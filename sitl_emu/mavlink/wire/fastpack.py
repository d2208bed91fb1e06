"""The one encoder: MAVLink 2 frames of all the vehicle sends, the bytes pymavlink's `msg.pack(mav)` makes, cheaper.

pymavlink stays the parser and the source of each message's metadata (field order, types, struct layout,
crc_extra, its encode functions' defaults); this module is the one encoder. pymavlink builds a message object, a
header object and a bytearray per message and checksums through two wrapper objects; at ~700 messages per simulated
second per vehicle that was most of the cost of the link. Here:
- `ENCODER.<name>_encode(...)` takes the same arguments (and defaults) as pymavlink's `MAVLink.<name>_encode`
  (positionally, as every caller passes them) and returns a `Packed`: the message's spec and its field values in
  wire order, packed when sent (as pymavlink packs a message object when it is sent, so a value out of its wire range
  fails at the same place).
- `frame_message(msg, seq, sysid, compid)` frames a Packed as MAVLink 2: trailing zero bytes of the payload cut (at
  least one byte kept), compat flags 0, incompat flags as given (MAVLINK_IFLAG_SIGNED for a frame wire/signing.py
  then signs), X.25 (CRC-16/MCRF4XX) checksum over header, payload and the message's crc_extra. The caller owns the
  sequence number (Endpoint: its `seq`, one per link).

What this module reads of pymavlink (tests/sitl_emu/mavlink/wire/test_pymavlink_internals.py fails when a new
pymavlink changes it; pyproject.toml bounds the version to the newest checked): the dialect module's
`MAVLink_<name>_message` classes with their `id`, `msgname`, `fieldnames`, `fieldtypes`, `ordered_fieldnames`,
`array_lengths`, `crc_extra` and `unpacker` (a struct.Struct of the whole payload in wire order), and the defaults
of `MAVLink.<name>_encode`. From that metadata each class gets a MessageSpec, whose one `encode` puts the arguments
in the order pymavlink's own generated `pack()` expression does (arrays element by element, char arrays whole), so
bad values fail the same way (struct.error, IndexError...); compiled, with no code generated per message.
tests/sitl_emu/mavlink/wire/test_fastpack.py checks the bytes against pymavlink's for every message of the dialect.
"""
from __future__ import annotations

import binascii
import contextlib
import struct
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, Final

from pymavlink.dialects.v20 import development as dialect

if TYPE_CHECKING:
    from pymavlink.dialects.v20.development import MAVLink

_mcrf4xx: Callable[[bytes, int], int] | None
try:  # pymavlink's own CRC dependency (a C extension); the stdlib fallback below gives the same numbers
    from fastcrc.crc16 import mcrf4xx as _mcrf4xx
except ImportError:  # pragma: no cover - depends on the installed pymavlink
    _mcrf4xx = None

MAGIC_V2: Final = b"\xfd"
_HEADER: Final = struct.Struct("<BBBBBB3s")  # len, incompat, compat, seq, sysid, compid, msgid (24 bit): after magic
_CRC: Final = struct.Struct("<H")
# The packers as Final names: compiled, frame_message then calls them directly (no module dict or method look-up)
_pack_header: Final = _HEADER.pack
_pack_crc: Final = _CRC.pack
_rstrip: Final = bytes.rstrip  # compiled, a call of the method itself skips looking it up on each payload
_BITREV = bytes(int(f"{i:08b}"[::-1], 2) for i in range(256))


def _crc_hqx_reflected(data: bytes, crc: int = 0xFFFF) -> int:
    """CRC-16/MCRF4XX from the stdlib: binascii.crc_hqx is the same polynomial unreflected, so reflect in and out."""
    rev = _BITREV
    crc = binascii.crc_hqx(data.translate(rev), rev[crc >> 8] | (rev[crc & 0xFF] << 8))
    return rev[crc >> 8] | (rev[crc & 0xFF] << 8)


x25_crc: Final[Callable[[bytes, int], int]] = _mcrf4xx if _mcrf4xx is not None else _crc_hqx_reflected


Term = tuple[int, int]  # one argument of an encode call on the wire: (its position, its array length or 0)


class MessageSpec:
    """A message as fastpack encodes it: its id, name and checksum seed, its struct, and its encode call.

    `encode(*args)` takes pymavlink's `MAVLink.<name>_encode` arguments, positionally: the fields in their declared
    order, the last `len(defaults)` of them optional. It puts them in wire order (`wire`: per argument on the wire,
    its position and array length) as pymavlink's generated pack() does: an array element by element (a short one
    fails with IndexError), a char array (bytes) whole. Most messages declare their scalar fields in wire order
    already: their arguments are their values; a message without arrays picks them (`picks`)."""

    def __init__(self, msg_id: int, name: str, crc_extra: bytes, pack: Callable[..., bytes], arity: int,
                 defaults: tuple[Any, ...], wire: tuple[Term, ...]) -> None:
        self.msg_id = msg_id
        self.msg_id_bytes = msg_id.to_bytes(3, "little")  # as the header carries it
        self.name = name
        self.crc_extra = crc_extra  # one byte, appended to the checksummed data
        self.pack = pack  # the class's struct: wire-ordered values -> whole payload
        self.arity = arity  # how many arguments encode takes
        self.defaults = defaults  # the values of the last arguments when a call leaves them out
        self.wire = wire
        # without arrays: the arguments' positions in wire order (most messages: in order already)
        self.picks = None if any(length for _, length in wire) else tuple(position for position, _ in wire)
        self.in_wire_order = self.picks == tuple(range(arity))

    def encode(self, *args: Any) -> Packed:
        if len(args) != self.arity:
            args = self._completed(args)
        if self.in_wire_order:
            return Packed(self, args)
        picks = self.picks
        if picks is not None:
            return Packed(self, tuple(args[i] for i in picks))
        values: list[Any] = []
        for position, length in self.wire:
            value = args[position]
            if length:
                elements = value[:length]
                if len(elements) < length:
                    raise IndexError(f"{self.name}: an array of {len(elements)} values where {length} are sent")
                values.extend(elements)
            else:
                values.append(value)
        return Packed(self, tuple(values))

    def _completed(self, args: tuple[Any, ...]) -> tuple[Any, ...]:
        """The arguments with the defaults of those left out, or TypeError as for a Python call."""
        missing = self.arity - len(args)
        if missing < 0 or missing > len(self.defaults):
            raise TypeError(f"{self.name.lower()}_encode takes {self.arity - len(self.defaults)} to {self.arity} "
                            f"arguments ({len(args)} given)")
        return args + self.defaults[len(self.defaults) - missing:]


class Packed:
    """A message as the encoder returns it: its spec and its field values in wire order (arrays flattened).

    Endpoint.send() frames it directly; the first framing keeps the packed payload (`body`, trailing zeros cut), so
    a message both links send is packed once (telemetry/streams.py SharedBuilds). It also packs like a pymavlink
    message, so a plain pymavlink `MAVLink.send()` can send it too.
    """

    __slots__ = ("body", "spec", "values")

    def __init__(self, spec: MessageSpec, values: tuple[Any, ...]) -> None:
        self.spec = spec
        self.values = values
        self.body: bytes | None = None

    def get_type(self) -> str:
        return self.spec.name

    def pack(self, mav: MAVLink, force_mavlink1: bool = False) -> bytes:
        if force_mavlink1:
            raise ValueError("Packed messages are MAVLink 2 only")
        return frame_message(self, mav.seq, mav.srcSystem, mav.srcComponent)


def frame_message(msg: Packed, seq: int, sysid: int, compid: int, incompat_flags: int = 0) -> bytes:
    """The MAVLink 2 frame of a Packed, exactly as pymavlink's MAVLink_message._pack builds it, without a signature
    block (a struct.error etc. for a value out of range)."""
    spec = msg.spec
    body = msg.body
    if body is None:
        pack = spec.pack  # a local: compiled, a starred call of an attribute looks it up by name
        payload = pack(*msg.values)
        body = msg.body = _rstrip(payload, b"\0") or payload[:1]  # trailing zeros cut, one byte kept
    head = _pack_header(len(body), incompat_flags, 0, seq, sysid, compid, spec.msg_id_bytes) + body
    return MAGIC_V2 + head + _pack_crc(x25_crc(head + spec.crc_extra, 0xFFFF))


# --- per-class specs -------------------------------------------------------------------------------------------------
_SPECS_BY_CLASS: dict[type, MessageSpec] = {}


def spec_for_class(cls: type) -> MessageSpec:
    """The spec of a pymavlink message class (built once, then cached)."""
    spec = _SPECS_BY_CLASS.get(cls)
    if spec is None:
        spec = _build_spec(cls)
        _SPECS_BY_CLASS[cls] = spec
    return spec


def _wire_terms(cls: Any) -> tuple[Term, ...]:
    """The wire order of the class's encode arguments, as pymavlink's generated pack() passes them to the struct:
    an array element by element, a char array (bytes) whole."""
    position = {name: i for i, name in enumerate(cls.fieldnames)}
    types = dict(zip(cls.fieldnames, cls.fieldtypes, strict=True))
    return tuple((position[name], length if types[name] != "char" else 0)
                 for name, length in zip(cls.ordered_fieldnames, cls.array_lengths, strict=True))


def _build_spec(cls: Any) -> MessageSpec:
    return MessageSpec(cls.id, cls.msgname, bytes((cls.crc_extra,)), cls.unpacker.pack, len(cls.fieldnames),
                       _encode_defaults(cls), _wire_terms(cls))


def _encode_defaults(cls: Any) -> tuple[Any, ...]:
    method = getattr(dialect.MAVLink, f"{cls.msgname.lower()}_encode", None)
    source = method if method is not None else cls.__init__
    return source.__defaults__ or ()


class Encoder:
    """`ENCODER.attitude_encode(...)` -> Packed, the same call as pymavlink's `mav.attitude_encode(...)`."""

    def __init__(self) -> None:
        self._encoders: dict[str, Callable[..., Packed]] = {}  # by attribute name, built on first use

    def __getattr__(self, attr: str) -> Callable[..., Packed]:
        """Only called for a name that is not an attribute yet: build its encoder once."""
        encode = self._encoders.get(attr)
        if encode is None:
            if not attr.endswith("_encode"):
                raise AttributeError(attr)
            cls = dialect.__dict__.get(f"MAVLink_{attr[:-len('_encode')]}_message")
            if cls is None:
                raise AttributeError(attr)
            encode = self._encoders[attr] = spec_for_class(cls).encode
            # In pure Python later look-ups are then plain attribute hits, which never reach this method (reaching
            # it costs a failed look-up first). The compiled Encoder has no instance __dict__: the dict above serves.
            with contextlib.suppress(AttributeError):
                setattr(self, attr, encode)
        return encode


ENCODER = Encoder()
