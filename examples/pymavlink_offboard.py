#!/usr/bin/env python3
"""A minimal PX4 offboard flight with pymavlink: copy it and change the waypoints.

Start a vehicle first, then run this script:

    sitl-emu serve                              # or PX4 SITL: make px4_sitl sihsim_quadx
    python examples/pymavlink_offboard.py       # listens on UDP 14540, where PX4's API link sends

The sequence every PX4 offboard client needs (PX4 refuses OFFBOARD without a setpoint younger than 1 s):
stream setpoints first, then arm, then switch to OFFBOARD, and keep streaming (here 20 Hz) for the whole flight.
A vehicle that flew before may wait disarmed in a mode that cannot arm (after an OFFBOARD flight PX4 stays in OFFBOARD
with HEARTBEAT system_status UNINIT): the script then switches it to Hold first, as a ground station would.
"""

from __future__ import annotations

import argparse
import time

from pymavlink import mavutil

MASK_POSITION_YAW = 2552  # POSITION_TARGET_TYPEMASK: ignore velocity, acceleration and yaw rate
OFFBOARD = 6  # PX4 main mode (px4_custom_mode.h)
HOLD = (4, 3)  # PX4 main mode AUTO, sub-mode LOITER: Hold, a mode that can arm wherever the position is known
MAV_STATE_STANDBY = 3  # HEARTBEAT system_status of a disarmed PX4 whose arming checks pass in its current mode
PERIOD_S = 0.05
READY_TIMEOUT_S = 60.0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--url", default="udpin:0.0.0.0:14540", help="pymavlink connection string")
    parser.add_argument("--speed", type=float, default=1.0,
                        help="the vehicle's speed factor (sitl-emu serve --speed N): the flight's timing follows it")
    args = parser.parse_args(argv)
    mav = mavutil.mavlink_connection(args.url, source_system=255, source_component=190)
    print("waiting for the vehicle's heartbeat on", args.url)
    if mav.wait_heartbeat(timeout=30) is None:
        raise SystemExit(f"no heartbeat on {args.url}: start `sitl-emu serve` or PX4 SITL first")
    print(f"vehicle {mav.target_system} found; waiting until it is ready to arm")
    wait_ready(mav, READY_TIMEOUT_S / args.speed)
    pos = wait_position(mav)

    hover = (pos[0], pos[1], -3.0)  # NED: 3 m up
    stream(mav, hover, 0.5, args.speed)  # 10 setpoints before anything else
    command(mav, mavutil.mavlink.MAV_CMD_COMPONENT_ARM_DISARM, 1)
    command(mav, mavutil.mavlink.MAV_CMD_DO_SET_MODE, mavutil.mavlink.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, OFFBOARD)
    for target, seconds in ((hover, 10), ((hover[0] + 3, hover[1], -3.0), 6), (hover, 6)):
        print("going to", target)
        stream(mav, target, seconds, args.speed)
    command(mav, mavutil.mavlink.MAV_CMD_NAV_LAND)
    print("landing; waiting for the vehicle to disarm")
    heartbeat = mav.recv_match(type="HEARTBEAT", blocking=True, timeout=30)
    while heartbeat is not None and heartbeat.base_mode & mavutil.mavlink.MAV_MODE_FLAG_SAFETY_ARMED:
        heartbeat = mav.recv_match(type="HEARTBEAT", blocking=True, timeout=30)
    print("landed and disarmed")
    return 0


def wait_ready(mav: mavutil.mavfile, timeout_s: float) -> None:
    """Wait until the vehicle can arm: HEARTBEAT system_status STANDBY. PX4 says UNINIT while its arming checks fail
    in the current mode: while the estimator starts, and in a mode that cannot arm, such as OFFBOARD without
    setpoints, where a vehicle stays after an OFFBOARD flight. A disarmed vehicle in any mode but Hold is switched to
    Hold (again every 5 s while it is not ready); after `timeout_s` the script says what it saw and stops."""
    deadline, next_ask, heartbeat = time.monotonic() + timeout_s, 0.0, None
    while time.monotonic() < deadline:
        msg = mav.recv_match(type="HEARTBEAT", blocking=True, timeout=1)
        if msg is None or msg.get_srcSystem() != mav.target_system:
            continue
        heartbeat = msg
        if msg.system_status == MAV_STATE_STANDBY:
            return
        armed = msg.base_mode & mavutil.mavlink.MAV_MODE_FLAG_SAFETY_ARMED
        if not armed and ((msg.custom_mode >> 16) & 0xFF, msg.custom_mode >> 24) != HOLD and \
                time.monotonic() >= next_ask:
            print(f"the vehicle is disarmed in {mavutil.mode_string_v10(msg)}, where it cannot arm: switching to Hold")
            mav.mav.command_long_send(mav.target_system, mav.target_component, mavutil.mavlink.MAV_CMD_DO_SET_MODE,
                                      0, mavutil.mavlink.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, *HOLD, 0, 0, 0, 0)
            next_ask = time.monotonic() + 5.0
    seen = "no HEARTBEAT" if heartbeat is None else (
        f"HEARTBEAT system_status {heartbeat.system_status}, mode {mavutil.mode_string_v10(heartbeat)}")
    raise SystemExit(f"the vehicle was not ready to arm (HEARTBEAT system_status {MAV_STATE_STANDBY}, STANDBY) "
                     f"within {timeout_s:g} s; last seen: {seen}. Is it armed, or are its pre-flight checks failing?")


def wait_position(mav: mavutil.mavfile) -> tuple[float, float, float]:
    msg = mav.recv_match(type="LOCAL_POSITION_NED", blocking=True, timeout=10)
    if msg is None:
        raise SystemExit("no LOCAL_POSITION_NED from the vehicle: is its position estimate ready?")
    return (msg.x, msg.y, msg.z)


def stream(mav: mavutil.mavfile, target: tuple[float, float, float], seconds: float, speed: float = 1.0) -> None:
    """Send position setpoints at 20 Hz (and our GCS heartbeat at 1 Hz) for `seconds`, of the vehicle's time."""
    end = time.monotonic() + seconds / speed
    next_heartbeat = 0.0
    while time.monotonic() < end:
        now = time.monotonic()
        if now >= next_heartbeat:
            mav.mav.heartbeat_send(mavutil.mavlink.MAV_TYPE_GCS, mavutil.mavlink.MAV_AUTOPILOT_INVALID, 0, 0, 0)
            next_heartbeat = now + 1.0 / speed
        mav.mav.set_position_target_local_ned_send(
            0, mav.target_system, mav.target_component, mavutil.mavlink.MAV_FRAME_LOCAL_NED, MASK_POSITION_YAW,
            *target, 0, 0, 0, 0, 0, 0, 0.0, 0)
        while mav.recv_match(blocking=False) is not None:  # drain telemetry
            pass
        time.sleep(PERIOD_S / speed)


def command(mav: mavutil.mavfile, cmd: int, *params: float) -> None:
    """COMMAND_LONG and its COMMAND_ACK (PX4 answers within a few ms, well inside the 1 s setpoint timeout)."""
    values = list(params) + [0.0] * (7 - len(params))
    mav.mav.command_long_send(mav.target_system, mav.target_component, cmd, 0, *values)
    ack = mav.recv_match(type="COMMAND_ACK", blocking=True, timeout=3)
    result = "no answer" if ack is None else mavutil.mavlink.enums["MAV_RESULT"][ack.result].name
    print(f"command {cmd}: {result}")
    if ack is None or ack.result != mavutil.mavlink.MAV_RESULT_ACCEPTED:
        raise SystemExit(f"command {cmd} was not accepted ({result})")


if __name__ == "__main__":
    raise SystemExit(main())
