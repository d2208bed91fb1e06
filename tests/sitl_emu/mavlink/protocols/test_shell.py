"""MAVLink shell over SERIAL_CONTROL (reference section 8), with real pymavlink messages in and out."""

from __future__ import annotations

import pytest
from support.handler_ctx import Client, FakeVehicle, MemoryContext

from sitl_emu.mavlink.protocols.shell import (
    CHUNKS_PER_TICK,
    MAX_CHUNK,
    SERIAL_CONTROL_FLAG_REPLY,
    ShellBridge,
)
from sitl_emu.px4 import MavCmd, Severity

EXCLUSIVE_RESPOND = 6  # what PX4's Tools/mavlink_shell.py sends


@pytest.fixture()
def setup() -> tuple[ShellBridge, MemoryContext, Client]:
    return ShellBridge(), MemoryContext(FakeVehicle()), Client()


def _serial(client: Client, text: bytes, flags: int = EXCLUSIVE_RESPOND, device: int = 10) -> object:
    data = list(text) + [0] * (70 - len(text))
    return client.msg("SERIAL_CONTROL", device, flags, 0, 0, len(text), data)


def _type(bridge: ShellBridge, ctx: MemoryContext, client: Client, text: bytes, flags: int = EXCLUSIVE_RESPOND):
    for i in range(0, len(text), 70):
        bridge.handle(_serial(client, text[i:i + 70], flags), ctx)


def _read(bridge: ShellBridge, ctx: MemoryContext, ticks: int = 500) -> bytes:
    out = b""
    for _ in range(ticks):
        bridge.tick(ctx)
        msgs = ctx.take("SERIAL_CONTROL")
        if not msgs:
            break
        for m in msgs:
            assert m.device == 10 and m.flags == SERIAL_CONTROL_FLAG_REPLY
            assert 0 < m.count <= MAX_CHUNK
            out += bytes(m.data[: m.count])
    return out


def test_no_prompt_on_open_then_echo_run_and_prompt(setup):
    bridge, ctx, client = setup
    _type(bridge, ctx, client, b"\n")
    assert _read(bridge, ctx) == b"\npxh> "
    _type(bridge, ctx, client, b"param get MAV_SYS_ID\n")
    assert _read(bridge, ctx) == b"param get MAV_SYS_ID\n1\npxh> "


def test_commander_arm_goes_to_the_vehicle_and_its_log_line_comes_back(setup):
    bridge, ctx, client = setup
    vehicle = ctx.vehicle

    def react(cmd):
        vehicle.report(Severity.INFO, "commander", "Armed by internal command")
    vehicle.on_command = react
    _type(bridge, ctx, client, b"commander arm\n")
    out = _read(bridge, ctx)
    assert out == b"commander arm\nINFO  [commander] Armed by internal command\npxh> "
    (cmd,) = vehicle.commands
    assert cmd.command == MavCmd.COMPONENT_ARM_DISARM and not cmd.from_external


def test_events_while_open_are_streamed(setup):
    bridge, ctx, client = setup
    ctx.vehicle.report(Severity.INFO, "commander", "Ready for takeoff!")  # before the session: not shown
    _type(bridge, ctx, client, b"\n")
    _read(bridge, ctx)
    ctx.vehicle.report(Severity.INFO, "commander", "Takeoff detected")
    assert _read(bridge, ctx) == b"INFO  [commander] Takeoff detected\n"


def test_long_output_is_chunked_at_70_bytes(setup):
    bridge, ctx, client = setup
    _type(bridge, ctx, client, b"param show\n")
    bridge.tick(ctx)
    first_tick = ctx.take("SERIAL_CONTROL")
    assert len(first_tick) == CHUNKS_PER_TICK
    assert all(m.count == MAX_CHUNK for m in first_tick)
    out = b"".join(bytes(m.data[: m.count]) for m in first_tick) + _read(bridge, ctx)
    assert out.endswith(b"parameters used.\npxh> ")
    assert b"MAV_SYS_ID" in out


def test_line_split_across_messages(setup):
    bridge, ctx, client = setup
    _type(bridge, ctx, client, b"param get ")
    _type(bridge, ctx, client, b"MAV_SYS_ID\n")
    assert _read(bridge, ctx).endswith(b"\n1\npxh> ")


def test_control_bytes_are_ignored(setup):
    bridge, ctx, client = setup
    _type(bridge, ctx, client, b"\x03param get MAV_SYS_ID\n")
    assert _read(bridge, ctx) == b"param get MAV_SYS_ID\n1\npxh> "


def test_message_without_respond_runs_then_closes(setup):
    bridge, ctx, client = setup
    _type(bridge, ctx, client, b"commander land\n", flags=0)
    assert [c.command for c in ctx.vehicle.commands] == [MavCmd.NAV_LAND]
    assert not bridge.is_open
    assert _read(bridge, ctx) == b""


def test_close_message_ends_session(setup):
    bridge, ctx, client = setup
    _type(bridge, ctx, client, b"\n")
    assert bridge.is_open
    bridge.handle(_serial(client, b"", flags=0), ctx)
    assert not bridge.is_open
    ctx.vehicle.report(Severity.INFO, "commander", "Landing detected")
    assert _read(bridge, ctx) == b""


@pytest.mark.parametrize(("device", "flags"),
                         [(0, EXCLUSIVE_RESPOND), (10, EXCLUSIVE_RESPOND | SERIAL_CONTROL_FLAG_REPLY)])
def test_other_devices_and_replies_are_ignored(setup, device, flags):
    bridge, ctx, client = setup
    bridge.handle(_serial(client, b"commander arm\n", flags=flags, device=device), ctx)
    assert not bridge.is_open
    assert ctx.vehicle.commands == []


def test_endless_line_is_cut_and_memory_stays_bounded(setup):
    bridge, ctx, client = setup
    for _ in range(100):
        _type(bridge, ctx, client, b"x" * 70)
    _type(bridge, ctx, client, b"\n")
    out = _read(bridge, ctx)
    assert out.endswith(b"\nInvalid command: " + b"x" * 1024 + b"\ntype 'help' for a list of commands\npxh> ")


def test_listener_works_over_the_mavlink_shell(setup):
    bridge, ctx, client = setup
    _type(bridge, ctx, client, b"listener vehicle_status\n")
    out = _read(bridge, ctx).decode()
    assert out.startswith("listener vehicle_status\n\nTOPIC: vehicle_status\n vehicle_status\n    timestamp: ")
    assert "    arming_state: 1\n" in out and out.endswith("pxh> ")


def test_listener_n_prints_as_the_topic_is_published_then_the_prompt_then_waiting_input(setup):
    bridge, ctx, client = setup
    vehicle = ctx.vehicle
    _type(bridge, ctx, client, b"listener vehicle_status -n 2\n")
    first = _read(bridge, ctx).decode()
    assert "TOPIC: vehicle_status instance 0 #1" in first and "pxh> " not in first
    _type(bridge, ctx, client, b"ver\n")  # waits until the listener has ended, as in PX4's shell pipe
    assert _read(bridge, ctx) == b""
    vehicle.time_us = 500_000  # vehicle_status: 2 Hz
    rest = _read(bridge, ctx).decode()
    assert rest.index("TOPIC: vehicle_status instance 0 #2") < rest.index("pxh> ver\nHW arch: PX4_SITL")
    assert rest.endswith("pxh> ")
