#!/usr/bin/env python3
"""A minimal PX4 offboard flight with pymavlink: copy it and change the waypoints.

Start a vehicle first, then run this script:

    sitl-emu serve                              # or PX4 SITL: make px4_sitl sihsim_quadx
    python examples/pymavlink_offboard.py       # listens on UDP 14540, where PX4's API link sends

The sequence every PX4 offboard client needs (PX4 refuses OFFBOARD without a setpoint younger than 1 s):
stream setpoints first, then arm, then switch to OFFBOARD, and keep streaming (here 20 Hz) for the whole flight.
"""

from __future__ import annotations

import argparse
import time

from pymavlink import mavutil

MASK_POSITION_YAW = 2552  # POSITION_TARGET_TYPEMASK: ignore velocity, acceleration and yaw rate
OFFBOARD = 6  # PX4 main mode (px4_custom_mode.h)
PERIOD_S = 0.05


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--url", default="udpin:0.0.0.0:14540", help="pymavlink connection string")
    args = parser.parse_args()
    mav = mavutil.mavlink_connection(args.url, source_system=255, source_component=190)
    print("waiting for the vehicle's heartbeat on", args.url)
    if mav.wait_heartbeat(timeout=30) is None:
        raise SystemExit(f"no heartbeat on {args.url}: start `sitl-emu serve` or PX4 SITL first")
    print(f"vehicle {mav.target_system} found; waiting until it is ready to arm")
    while mav.recv_match(type="HEARTBEAT", blocking=True, timeout=30).system_status != 3:  # MAV_STATE_STANDBY
        pass
    pos = wait_position(mav)

    hover = (pos[0], pos[1], -3.0)  # NED: 3 m up
    stream(mav, hover, 0.5)  # 10 setpoints before anything else
    command(mav, mavutil.mavlink.MAV_CMD_COMPONENT_ARM_DISARM, 1)
    command(mav, mavutil.mavlink.MAV_CMD_DO_SET_MODE, mavutil.mavlink.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, OFFBOARD)
    for target, seconds in ((hover, 10), ((hover[0] + 3, hover[1], -3.0), 6), (hover, 6)):
        print("going to", target)
        stream(mav, target, seconds)
    command(mav, mavutil.mavlink.MAV_CMD_NAV_LAND)
    print("landing; waiting for the vehicle to disarm")
    heartbeat = mav.recv_match(type="HEARTBEAT", blocking=True, timeout=30)
    while heartbeat is not None and heartbeat.base_mode & mavutil.mavlink.MAV_MODE_FLAG_SAFETY_ARMED:
        heartbeat = mav.recv_match(type="HEARTBEAT", blocking=True, timeout=30)
    print("landed and disarmed")


def wait_position(mav: mavutil.mavfile) -> tuple[float, float, float]:
    msg = mav.recv_match(type="LOCAL_POSITION_NED", blocking=True, timeout=10)
    if msg is None:
        raise SystemExit("no LOCAL_POSITION_NED from the vehicle: is its position estimate ready?")
    return (msg.x, msg.y, msg.z)


def stream(mav: mavutil.mavfile, target: tuple[float, float, float], seconds: float) -> None:
    """Send position setpoints at 20 Hz (and our GCS heartbeat at 1 Hz) for `seconds`."""
    end = time.monotonic() + seconds
    next_heartbeat = 0.0
    while time.monotonic() < end:
        now = time.monotonic()
        if now >= next_heartbeat:
            mav.mav.heartbeat_send(mavutil.mavlink.MAV_TYPE_GCS, mavutil.mavlink.MAV_AUTOPILOT_INVALID, 0, 0, 0)
            next_heartbeat = now + 1.0
        mav.mav.set_position_target_local_ned_send(
            0, mav.target_system, mav.target_component, mavutil.mavlink.MAV_FRAME_LOCAL_NED, MASK_POSITION_YAW,
            *target, 0, 0, 0, 0, 0, 0, 0.0, 0)
        while mav.recv_match(blocking=False) is not None:  # drain telemetry
            pass
        time.sleep(PERIOD_S)


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
    main()
