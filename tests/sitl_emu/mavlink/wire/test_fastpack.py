"""The one encoder (fastpack) sends exactly the bytes pymavlink's `msg.pack(mav)` would.

Table-driven over pymavlink's own messages: every message class of the dialect (and PROTOCOL_VERSION, which the
emulator defines from common.xml in pymavlink's shape), one test per property, each reporting every message that
breaks it. Then every telemetry builder on real and extreme vehicle states, and end to end over UDP everything a
session with a ground station makes the vehicle send (streams, acks, params, mission, shell, status texts), one
sequence number per link.
"""

from __future__ import annotations

import itertools
import math
import random
from collections.abc import Callable
from typing import Any

import pytest
from pymavlink.dialects.v20 import development as dialect
from support.fakes import HOME, Harness
from support.handler_ctx import make_snapshot
from support.ports import pending_datagrams

from sitl_emu.mavlink.telemetry.streams import BUILDERS, ON_REQUEST
from sitl_emu.mavlink.version import ProtocolVersionMessage
from sitl_emu.mavlink.wire import extra_messages, fastpack
from sitl_emu.mavlink.wire.signing import IFLAG_SIGNED, sign_frame
from sitl_emu.px4 import MavCmd, NavState
from sitl_emu.types import HomePosition, OffboardControlMode, TrajectorySetpoint, VehicleCommand
from sitl_emu.vehicle.vehicle import Vehicle

# (test_commands_wire.py adds PROTOCOL_VERSION to the dialect's map for its client: not a dialect class here)
DIALECT_CLASSES = sorted((c for c in dialect.mavlink_map.values() if c is not ProtocolVersionMessage),
                         key=lambda c: c.id)
TABLE = [*DIALECT_CLASSES, ProtocolVersionMessage]
FLOAT_EDGES = (0.0, -0.0, 1.5, -2.75e-3, math.nan, math.inf, -math.inf, 3.4e38, -1.0e-45)
NAN = math.nan
SIZES = {"char": 1, "int8_t": 1, "uint8_t": 1, "int16_t": 2, "uint16_t": 2, "int32_t": 4, "uint32_t": 4, "float": 4,
         "int64_t": 8, "uint64_t": 8, "double": 8}  # MAVLink's types, bytes on the wire


def _scalar(ctype: str, rng: random.Random) -> Any:
    if ctype in ("float", "double"):
        return rng.choice([*FLOAT_EDGES, rng.uniform(-1e7, 1e7)])
    bits = int("".join(c for c in ctype if c.isdigit()) or 8)
    if ctype.startswith("u") or ctype == "char":
        return rng.choice([0, 1, 2**bits - 1, rng.randrange(2**bits)])
    low, high = -(2 ** (bits - 1)), 2 ** (bits - 1) - 1
    return rng.choice([0, -1, low, high, rng.randrange(low, high + 1)])


def _args(cls: Any, rng: random.Random) -> list[Any]:
    """Constructor arguments in field order: edge and random values, strings of every length, arrays."""
    types = dict(zip(cls.fieldnames, cls.fieldtypes, strict=True))
    lengths = dict(zip(cls.ordered_fieldnames, cls.array_lengths, strict=True))
    args: list[Any] = []
    for name in cls.fieldnames:
        ctype, length = types[name], lengths[name]
        if ctype == "char":
            args.append(bytes(rng.randrange(1, 128) for _ in range(rng.randrange(length + 1))))
        elif length:
            args.append([_scalar(ctype, rng) for _ in range(length)])
        else:
            args.append(_scalar(ctype, rng))
    return args


def _parse(frame: bytes) -> list[Any]:
    parser = dialect.MAVLink(None)
    parser.robust_parsing = True
    return parser.parse_buffer(frame) or []


def _breaking(check: Callable[[Any], object], table: list[Any] = TABLE) -> list[str]:
    """The messages of the table for which `check(cls)` fails (an assertion or any error), as 'NAME: why'."""
    broken = []
    for cls in table:
        try:
            check(cls)
        except Exception as err:
            broken.append(f"{cls.msgname}: {type(err).__name__} {err}"[:300])
    return broken


def _mav(rng: random.Random) -> Any:
    mav = dialect.MAVLink(None, srcSystem=rng.randrange(1, 256), srcComponent=rng.randrange(256))
    mav.seq = rng.randrange(256)
    return mav


def test_fastpack_frames_every_message_as_pymavlink_packs_it():
    def check(cls: Any) -> None:
        rng = random.Random(cls.id)
        encode = fastpack.spec_for_class(cls).encode
        for _ in range(6):
            args, mav = _args(cls, rng), _mav(rng)
            expected = cls(*args).pack(mav)
            assert fastpack.frame_message(encode(*args), mav.seq, mav.srcSystem, mav.srcComponent) == expected
            if cls is not ProtocolVersionMessage:  # pymavlink's parser does not know #300
                (parsed,) = _parse(expected)
                assert parsed.get_type() == cls.msgname and parsed.get_seq() == mav.seq

    assert _breaking(check) == []


def test_fastpack_takes_pymavlinks_encode_arguments_and_defaults():
    def check(cls: Any) -> None:
        name = f"{cls.msgname.lower()}_encode"
        ours, theirs = getattr(fastpack.ENCODER, name), getattr(dialect.MAVLink, name)
        spec = fastpack.spec_for_class(cls)
        parameters = theirs.__code__.co_varnames[1:theirs.__code__.co_argcount]
        assert spec.arity == len(parameters) and spec.defaults == (theirs.__defaults__ or ())
        assert [parameters[position] for position, _ in spec.wire] == list(cls.ordered_fieldnames)
        required = len(cls.fieldnames) - len(theirs.__defaults__ or ())
        args = _args(cls, random.Random(cls.id + 7))[:required]
        mav = dialect.MAVLink(None, srcSystem=1, srcComponent=1)
        assert ours(*args).pack(mav) == getattr(mav, name)(*args).pack(mav)
        assert ours(*args).get_type() == cls.msgname

    assert _breaking(check, DIALECT_CLASSES) == []


def _only_first_field_set(cls: Any) -> tuple[list[Any], int]:
    """Arguments with every byte of the first field on the wire non-zero and all else zero, and that field's size."""
    types = dict(zip(cls.fieldnames, cls.fieldtypes, strict=True))
    lengths = dict(zip(cls.ordered_fieldnames, cls.array_lengths, strict=True))
    first = cls.ordered_fieldnames[0]
    args: list[Any] = []
    for name in cls.fieldnames:
        ctype, length = types[name], lengths[name]
        value: Any = b"\x01" * length if ctype == "char" else -1.0 if ctype in ("float", "double") else (
            -1 if ctype.startswith("int") else 2 ** (8 * SIZES[ctype]) - 1)  # the last byte is never zero
        if name != first:
            value = b"" if ctype == "char" else 0
        args.append([value] * length if length and ctype != "char" else value)
    return args, SIZES[types[first]] * max(lengths[first], 1)


def test_trailing_zero_bytes_are_cut_as_mavlink2_says_and_the_parser_fills_them_back():
    """MAVLink 2 payload truncation: the zero bytes at the end of the payload (extension fields included) are not
    sent, at least one byte is; a receiver reads the missing bytes as zero."""
    def check(cls: Any) -> None:
        encode = fastpack.spec_for_class(cls).encode
        args, first_size = _only_first_field_set(cls)
        frame = fastpack.frame_message(encode(*args), 0, 1, 1)
        assert frame[1] == first_size and len(frame) == 10 + first_size + 2
        if cls is not ProtocolVersionMessage:
            (parsed,) = _parse(frame)
            assert parsed.get_type() == cls.msgname
            sent = cls(*args)
            assert [getattr(parsed, f) for f in cls.fieldnames] == [getattr(sent, f) for f in cls.fieldnames]

    assert _breaking(check) == []


def test_an_all_zero_message_keeps_one_payload_byte():
    def check(cls: Any) -> None:
        types = dict(zip(cls.fieldnames, cls.fieldtypes, strict=True))
        lengths = dict(zip(cls.ordered_fieldnames, cls.array_lengths, strict=True))
        args = [b"" if types[n] == "char" else [0] * lengths[n] if lengths[n] else 0 for n in cls.fieldnames]
        frame = fastpack.frame_message(fastpack.spec_for_class(cls).encode(*args), 0, 1, 1)
        assert frame[1] == 1 and frame[10] == 0 and len(frame) == 13

    assert _breaking(check) == []


def test_the_checksum_covers_the_header_the_payload_and_the_messages_crc_extra():
    def check(cls: Any) -> None:
        frame = fastpack.frame_message(fastpack.spec_for_class(cls).encode(*_args(cls, random.Random(cls.id))), 9, 1, 1)
        crc = dialect.x25crc(frame[1:-2])
        crc.accumulate(bytes((cls.crc_extra,)))
        assert frame[-2:] == crc.crc.to_bytes(2, "little")

    assert _breaking(check) == []


def test_signed_frames_are_the_ones_pymavlink_signs():
    key = bytes(range(100, 132))

    def check(cls: Any) -> None:
        rng = random.Random(cls.id + 11)
        mav = _mav(rng)
        link_id, timestamp = rng.randrange(256), rng.randrange(1 << 48)
        mav.signing.secret_key, mav.signing.sign_outgoing, mav.signing.link_id = key, True, link_id
        mav.signing.timestamp = timestamp
        args = _args(cls, rng)
        frame = fastpack.frame_message(fastpack.spec_for_class(cls).encode(*args), mav.seq, mav.srcSystem,
                                       mav.srcComponent, IFLAG_SIGNED)
        assert sign_frame(frame, key, link_id, timestamp) == cls(*args).pack(mav)

    assert _breaking(check) == []


def test_checksum_fallback_without_fastcrc_gives_the_same_crc():
    rng = random.Random(5)
    for length in (0, 1, 2, 9, 64, 280):
        data = bytes(rng.randrange(256) for _ in range(length))
        crc = dialect.x25crc(data).crc
        assert fastpack._crc_hqx_reflected(data) == crc == fastpack.x25_crc(data, 0xFFFF)


def test_a_value_out_of_its_wire_range_fails_like_pymavlink():
    mav = dialect.MAVLink(None, srcSystem=1, srcComponent=1)
    for args in ((300, b"x", 0, 0), (-1, b"x", 0, 0), (0, b"x", -1, 0), (0, b"x", 70000, 0), (0, b"x", 0, 256)):
        with pytest.raises(Exception) as theirs:
            mav.statustext_encode(*args).pack(mav)
        with pytest.raises(type(theirs.value)):
            fastpack.frame_message(fastpack.ENCODER.statustext_encode(*args), 0, 1, 1)
    with pytest.raises(IndexError):  # a short array, as pymavlink's element-by-element pack
        fastpack.ENCODER.attitude_quaternion_encode(0, 1, 0, 0, 0, 0, 0, 0, [0.0, 0.0])
    with pytest.raises(TypeError):  # an array pymavlink cannot index
        fastpack.ENCODER.attitude_quaternion_encode(0, 1, 0, 0, 0, 0, 0, 0, 5)


def test_encode_takes_the_messages_arguments_and_no_more_or_fewer():
    assert fastpack.ENCODER.heartbeat_encode(6, 8, 0, 0, 0, 2).values[-1] == 2  # the default given
    for args in ((6, 8, 0, 0), (6, 8, 0, 0, 0, 3, 1)):
        with pytest.raises(TypeError):
            fastpack.ENCODER.heartbeat_encode(*args)


def test_extra_messages_take_their_arrays_as_pymavlink_takes_arrays():
    """The one encode serves the messages pymavlink lacks too: arrays sliced to their length (longer ones cut, any
    sequence), a short one an IndexError."""
    encode = extra_messages.EXTRA.esc_status_encode
    sent = fastpack.frame_message(encode(1, 2, [1, 2, 3, 4], (1.0,) * 4, [0.0] * 4), 0, 1, 1)
    assert fastpack.frame_message(encode(1, 2, range(1, 9), [1.0] * 5, (0.0,) * 4), 0, 1, 1) == sent
    with pytest.raises(IndexError):
        encode(1, 2, [1, 2, 3], [1.0] * 4, [0.0] * 4)


# --- telemetry builders ---------------------------------------------------------------------------------------------
class _Node:
    epoch_unix_us = 1_700_000_000_000_000


class _PymavlinkEncoder:
    """pymavlink's encoder behind fastpack's type (a compiled builder returns only a Packed): the message a builder
    gets is a Packed whose one value is pymavlink's own message object, which the test then packs with pymavlink."""

    SPEC = fastpack.MessageSpec(0xFFFFFF, "PYMAVLINK", b"\0", lambda *values: b"", 1, (), ((0, 0),))  # no such id

    def __init__(self, mav: Any) -> None:
        self._mav = mav
        self.calls = 0

    def __getattr__(self, name: str) -> Any:
        encode = getattr(self._mav, name)

        def reference(*args: Any) -> fastpack.Packed:
            self.calls += 1
            return fastpack.Packed(self.SPEC, (encode(*args),))

        return reference


class _BuilderCtx:
    """What a builder reads of its link, with pymavlink's encoder (the reference) or fastpack."""

    def __init__(self, pymavlink: bool) -> None:
        self.sysid, self.compid = 1, 1
        self.mav = dialect.MAVLink(None, srcSystem=1, srcComponent=1)
        self.encoder = _PymavlinkEncoder(self.mav) if pymavlink else fastpack.ENCODER
        self.node = _Node()


def _flight_snapshots() -> list[Any]:
    v = Vehicle()
    shots = []

    def run(seconds: float) -> None:
        for i in range(round(seconds * 250)):
            v.step()
            if i % 60 == 0:
                shots.append(v.snapshot())

    run(2.5)
    v.handle_command(VehicleCommand(MavCmd.COMPONENT_ARM_DISARM, (1.0, *(NAN,) * 6)))
    v.handle_command(VehicleCommand(MavCmd.NAV_TAKEOFF, (NAN,) * 7))
    run(5.0)
    v.offboard_input(OffboardControlMode(position=True), TrajectorySetpoint(position_ned_m=(3.0, -2.0, -4.0)))
    run(1.0)
    return shots


def _extreme_snapshots() -> list[Any]:
    huge, inf = 1e30, math.inf
    return [
        make_snapshot(time_us=2**40, pos_ned_m=(-1.5, 2.5, -1e4), vel_ned_m_s=(-30.0, 40.0, -5.0), lat_deg=-89.9,
                      lon_deg=-179.99, alt_amsl_m=-400.0, euler_rad=(-3.1, 1.5, -0.1), battery_voltage_v=-3.0,
                      battery_remaining=-0.5, armed=True, nav_state=NavState.OFFBOARD, thrust_setpoint=-1.0,
                      offboard_control=OffboardControlMode(velocity=True),
                      home=HomePosition(*HOME, (1.0, -2.0, 0.5), -2.0),
                      local_setpoint=TrajectorySetpoint((NAN, 1.0, NAN), (0.0, NAN, -1.0), (NAN,) * 3, NAN, 0.5),
                      attitude_setpoint_q_wxyz=(0.5, -0.5, 0.5, -0.5), rates_setpoint_rad_s=(NAN, -1.0, 2.0)),
        make_snapshot(time_us=2**63 // 1000, pos_ned_m=(NAN, inf, -inf), vel_ned_m_s=(NAN, inf, -inf),
                      acc_ned_m_s2=(inf, NAN, -inf), q_wxyz=(NAN, 0.0, 0.0, 1.0), rates_frd_rad_s=(inf, -inf, NAN),
                      euler_rad=(NAN, inf, -inf), lat_deg=NAN, lon_deg=inf, alt_amsl_m=huge, battery_voltage_v=huge,
                      battery_remaining=NAN, thrust_setpoint=NAN, armed=True, home=HomePosition(NAN, inf, -huge,
                      (NAN, inf, -inf), inf), local_setpoint=TrajectorySetpoint(), attitude_setpoint_q_wxyz=(NAN,) * 4),
    ]


def _outcome(builder: Any, ctx: Any, snap: Any, seq: int) -> Any:
    """The frame the builder's message makes (pymavlink packs the reference's), or the error it fails with."""
    try:
        msg = builder(ctx, snap)
        if msg is None:
            return None
        if msg.spec is _PymavlinkEncoder.SPEC:
            ctx.mav.seq = seq
            return msg.values[0].pack(ctx.mav)
        return fastpack.frame_message(msg, seq, 1, 1)
    except Exception as err:  # a value out of range: both encoders must refuse it alike
        return type(err)


@pytest.mark.parametrize("snaps", [_flight_snapshots, _extreme_snapshots], ids=["flight", "extreme"])
def test_every_telemetry_builder_sends_what_pymavlink_would(snaps):
    reference, fast = _BuilderCtx(pymavlink=True), _BuilderCtx(pymavlink=False)
    sent = 0
    for i, snap in enumerate(snaps()):
        for msg_id, builder in {**BUILDERS, **ON_REQUEST}.items():
            expected = _outcome(builder, reference, snap, i % 256)
            assert _outcome(builder, fast, snap, i % 256) == expected, (msg_id, snap.time_us)
            sent += isinstance(expected, bytes)
    assert sent > 20 and reference.encoder.calls > 20


# --- end to end -----------------------------------------------------------------------------------------------------
def _repacked(datagram: bytes) -> bytes:
    """The datagram as pymavlink packs the message it parses to (PROTOCOL_VERSION decoded by hand)."""
    seq, sysid, compid = datagram[4], datagram[5], datagram[6]
    mav = dialect.MAVLink(None, srcSystem=sysid, srcComponent=compid)
    mav.seq = seq
    if int.from_bytes(datagram[7:10], "little") == 300:
        payload = datagram[10:-2].ljust(ProtocolVersionMessage.unpacker.size, b"\0")
        v = ProtocolVersionMessage.unpacker.unpack(payload)
        return ProtocolVersionMessage(v[0], v[1], v[2], list(v[3:11]), list(v[11:19])).pack(mav)
    msg_id = int.from_bytes(datagram[7:10], "little")
    if msg_id in extra_messages.MESSAGE_IDS:  # not in pymavlink: check the frame's checksum with the message's seed
        spec = next(s for s in extra_messages.SPECS.values() if s.msg_id == msg_id)
        assert datagram[1] <= len(spec.pack(*spec.encode(*_zeros(spec)).values)), "payload longer than the message"
        crc = fastpack.x25_crc(datagram[1:-2] + spec.crc_extra, 0xFFFF)
        assert datagram[-2:] == crc.to_bytes(2, "little")
        return datagram
    (msg,) = _parse(datagram)
    assert msg.get_type() != "BAD_DATA"
    return msg.pack(mav)


def _zeros(spec: Any) -> list[Any]:
    """The encode arguments of an extra message, all zero."""
    fields = extra_messages._DEFINITIONS[spec.name][1]
    return [[0] * length if length else 0 for _, _, length in fields]


def test_a_gcs_session_over_udp_is_byte_identical_to_pymavlink_and_one_sequence_per_link():
    h = Harness(Vehicle(home=HOME), handler_classes=None, epoch_unix_us=1_700_000_000_000_000)
    try:
        raw: dict[str, list[bytes]] = {"api": [], "gcs": []}

        def io() -> None:
            h.node.step_io(h.vehicle.time_us)
            raw["api"] += pending_datagrams(h.api.sock)
            raw["gcs"] += pending_datagrams(h.gcs.sock)

        def run(seconds: float) -> None:
            for _ in range(round(seconds * 250)):
                h.vehicle.step()
                io()

        h.gcs.heartbeat()
        run(0.5)
        mav = h.gcs.mav
        h.gcs.send(mav.param_request_list_encode(1, 1))
        h.gcs.send(mav.param_request_read_encode(1, 1, b"MPC_XY_VEL_MAX", -1))
        h.gcs.send(mav.mission_request_list_encode(1, 1, 0))
        h.gcs.send(mav.mission_count_encode(1, 1, 3, 0))
        for msg_id, param2 in ((148, 0), (300, 0), (435, 0), (242, 0), (245, 0), (147, 0)):
            h.gcs.command_long(MavCmd.REQUEST_MESSAGE, msg_id, param2)
        h.gcs.command_long(MavCmd.COMPONENT_ARM_DISARM, 1.0)  # denied before the estimator is ready: a status text
        h.gcs.send(mav.serial_control_encode(10, 2, 0, 0, 5, list(b"help\n") + [0] * 65))
        run(4.0)
        h.gcs.heartbeat()
        h.gcs.command_long(MavCmd.COMPONENT_ARM_DISARM, 1.0)
        h.gcs.command_long(MavCmd.NAV_TAKEOFF, NAN, NAN, NAN, NAN, NAN, NAN, 2.5)
        run(3.0)
        seen: set[int] = set()
        for link, datagrams in raw.items():
            own = [d for d in datagrams if d[5:7] == b"\x01\x01"]  # not forwarded from the other client
            for d in own:
                assert _repacked(d) == d, (link, d.hex())
            seqs = [d[4] for d in own]
            assert all(b == (a + 1) % 256 for a, b in itertools.pairwise(seqs)), link
            seen |= {int.from_bytes(d[7:10], "little") for d in own}
        must = {0, 22, 44, 47, 77, 126, 148, 253, 300, 435, *BUILDERS} - {360}  # ORBIT_EXECUTION_STATUS: orbiting only
        assert must <= seen, sorted(must - seen)
    finally:
        h.close()
