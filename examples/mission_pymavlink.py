#!/usr/bin/env python3
"""Upload and fly a short PX4 mission with pymavlink: copy it and change the waypoints.

Start a vehicle first, then run this script:

    sitl-emu serve                              # or PX4 SITL: make px4_sitl sihsim_quadx
    python examples/mission_pymavlink.py        # listens on UDP 14540, where PX4's API link sends

The mission: take off to 5 m, two waypoints 10 m north and then 10 m east of home, return to launch. The upload is
the MAVLink mission protocol (MISSION_COUNT, a MISSION_ITEM_INT for each MISSION_REQUEST_INT, MISSION_ACK);
MAV_CMD_MISSION_START then arms the vehicle and flies it in AUTO.MISSION. The script prints each
MISSION_ITEM_REACHED and the vehicle's texts until the vehicle has landed and disarmed. It sends a ground
station's HEARTBEAT every second: PX4 sends its texts (STATUSTEXT) only to a link where a ground station is.
A vehicle that flew before may wait disarmed in a mode that cannot arm (after an OFFBOARD flight PX4 stays in OFFBOARD
with HEARTBEAT system_status UNINIT): the script then switches it to Hold first, as a ground station would.
"""

from __future__ import annotations

import argparse
import math
import time

from pymavlink import mavutil

ALT_M = 5.0
WAYPOINTS_NE_M = ((10.0, 0.0), (10.0, 10.0))
EARTH_RADIUS_M = 6371000.0
HOLD = (4, 3)  # PX4 main mode AUTO, sub-mode LOITER: Hold, a mode that can arm wherever the position is known
MAV_STATE_STANDBY = 3  # HEARTBEAT system_status of a disarmed PX4 whose arming checks pass in its current mode
READY_TIMEOUT_S = 60.0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--url", default="udpin:0.0.0.0:14540", help="pymavlink connection string")
    parser.add_argument("--timeout", type=float, default=180.0, help="give up after this many seconds")
    args = parser.parse_args(argv)
    mav = mavutil.mavlink_connection(args.url, source_system=255, source_component=190)
    print("waiting for the vehicle's heartbeat on", args.url)
    if mav.wait_heartbeat(timeout=30) is None:
        raise SystemExit(f"no heartbeat on {args.url}: start `sitl-emu serve` or PX4 SITL first")
    heartbeat(mav)
    home = wait_ready(mav)
    items = mission(home)
    upload(mav, items)
    print(f"uploaded {len(items)} items; starting the mission")
    command(mav, mavutil.mavlink.MAV_CMD_MISSION_START, 0, 0)  # "Executing Mission" arrives meanwhile
    follow(mav, len(items), time.monotonic() + args.timeout)
    return 0


def heartbeat(mav: mavutil.mavfile) -> None:
    mav.mav.heartbeat_send(mavutil.mavlink.MAV_TYPE_GCS, mavutil.mavlink.MAV_AUTOPILOT_INVALID, 0, 0, 0)


def wait_ready(mav: mavutil.mavfile, timeout_s: float = READY_TIMEOUT_S) -> tuple[float, float]:
    """Wait until the vehicle can arm (HEARTBEAT system_status STANDBY) and knows home; home's lat/lon.

    PX4 says UNINIT while its arming checks fail in the current mode: while the estimator starts, and in a mode that
    cannot arm, such as OFFBOARD without setpoints, where a vehicle stays after an OFFBOARD flight. A disarmed
    vehicle in any mode but Hold is switched to Hold (again every 5 s while it is not ready); after `timeout_s` the
    script says what it saw and stops."""
    deadline, next_ask, last = time.monotonic() + timeout_s, 0.0, None
    while time.monotonic() < deadline:
        msg = mav.recv_match(type="HEARTBEAT", blocking=True, timeout=1)
        if msg is None or msg.get_srcSystem() != mav.target_system:
            continue
        last = msg
        if msg.system_status == MAV_STATE_STANDBY:
            break
        armed = msg.base_mode & mavutil.mavlink.MAV_MODE_FLAG_SAFETY_ARMED
        if not armed and ((msg.custom_mode >> 16) & 0xFF, msg.custom_mode >> 24) != HOLD and \
                time.monotonic() >= next_ask:
            print(f"the vehicle is disarmed in {mavutil.mode_string_v10(msg)}, where it cannot arm: switching to Hold")
            mav.mav.command_long_send(mav.target_system, mav.target_component, mavutil.mavlink.MAV_CMD_DO_SET_MODE,
                                      0, mavutil.mavlink.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, *HOLD, 0, 0, 0, 0)
            next_ask = time.monotonic() + 5.0
    else:
        seen = "no HEARTBEAT" if last is None else (
            f"HEARTBEAT system_status {last.system_status}, mode {mavutil.mode_string_v10(last)}")
        raise SystemExit(f"the vehicle was not ready to arm (HEARTBEAT system_status {MAV_STATE_STANDBY}, STANDBY) "
                         f"within {timeout_s:g} s; last seen: {seen}. Is it armed, or are its pre-flight checks "
                         "failing?")
    msg = mav.recv_match(type="HOME_POSITION", blocking=True, timeout=30)
    if msg is None:
        raise SystemExit("no HOME_POSITION from the vehicle")
    return msg.latitude * 1e-7, msg.longitude * 1e-7


def offset(home: tuple[float, float], north_m: float, east_m: float) -> tuple[int, int]:
    """lat/lon (degE7) `north_m`, `east_m` from home (flat earth: fine for a few hundred metres)."""
    lat = home[0] + math.degrees(north_m / EARTH_RADIUS_M)
    lon = home[1] + math.degrees(east_m / (EARTH_RADIUS_M * math.cos(math.radians(home[0]))))
    return round(lat * 1e7), round(lon * 1e7)


def mission(home: tuple[float, float]) -> list[tuple[int, int, float, float, int, int, float]]:
    """(command, frame, param1, param2, x, y, z) per item; frame 6: global, altitude above home; 2: no position."""
    m = mavutil.mavlink
    rel, no_position = m.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT, m.MAV_FRAME_MISSION
    x, y = offset(home, 0.0, 0.0)
    items = [(m.MAV_CMD_NAV_TAKEOFF, rel, 0.0, 0.0, x, y, ALT_M)]
    for north, east in WAYPOINTS_NE_M:
        x, y = offset(home, north, east)
        items.append((m.MAV_CMD_NAV_WAYPOINT, rel, 0.0, 0.0, x, y, ALT_M))  # hold 0 s, acceptance NAV_ACC_RAD
    items.append((m.MAV_CMD_NAV_RETURN_TO_LAUNCH, no_position, 0.0, 0.0, 0, 0, 0.0))
    return items


def upload(mav: mavutil.mavfile, items: list[tuple[int, int, float, float, int, int, float]]) -> None:
    mav.mav.mission_count_send(mav.target_system, mav.target_component, len(items), 0)
    while True:
        msg = mav.recv_match(type=["MISSION_REQUEST_INT", "MISSION_REQUEST", "MISSION_ACK"], blocking=True,
                             timeout=5)
        if msg is None:
            raise SystemExit("the vehicle stopped answering the mission upload")
        if msg.get_type() == "MISSION_ACK":
            if msg.type != mavutil.mavlink.MAV_MISSION_ACCEPTED:
                raise SystemExit(f"mission refused: MAV_MISSION_RESULT {msg.type}")
            return
        cmd, frame, p1, p2, x, y, z = items[msg.seq]
        mav.mav.mission_item_int_send(mav.target_system, mav.target_component, msg.seq, frame, cmd, 0, 1,
                                      p1, p2, 0.0, math.nan, x, y, z, 0)


def command(mav: mavutil.mavfile, cmd: int, *params: float) -> None:
    p = [*params, *([0.0] * (7 - len(params)))]
    mav.mav.command_long_send(mav.target_system, mav.target_component, cmd, 0, *p)
    ack = mav.recv_match(type="COMMAND_ACK", blocking=True, timeout=5)
    if ack is None or ack.result != mavutil.mavlink.MAV_RESULT_ACCEPTED:
        raise SystemExit(f"command {cmd} refused: {ack.result if ack else 'no answer'}")


def follow(mav: mavutil.mavfile, count: int, deadline: float) -> None:
    """Print progress until the vehicle disarms after the mission."""
    reached, armed_seen, next_heartbeat = -1, False, 0.0
    chunks: dict[int, str] = {}  # a text longer than 50 characters comes in chunks with one id (MAVLink STATUSTEXT)
    while time.monotonic() < deadline:
        if time.monotonic() >= next_heartbeat:
            heartbeat(mav)
            next_heartbeat = time.monotonic() + 1.0
        msg = mav.recv_match(type=["MISSION_ITEM_REACHED", "STATUSTEXT", "HEARTBEAT"], blocking=True, timeout=5)
        if msg is None:
            continue
        kind = msg.get_type()
        if kind == "MISSION_ITEM_REACHED" and msg.seq != reached:
            reached = msg.seq
            print(f"reached item {reached} of {count}")
        elif kind == "STATUSTEXT":
            text = chunks.pop(msg.id, "") + msg.text
            if msg.id and len(msg.text) == 50:  # a full chunk: more of this text follows
                chunks[msg.id] = text
            else:
                print("vehicle:", text.strip())
        elif kind == "HEARTBEAT" and msg.get_srcSystem() == mav.target_system:
            armed = bool(msg.base_mode & mavutil.mavlink.MAV_MODE_FLAG_SAFETY_ARMED)
            armed_seen |= armed
            if armed_seen and not armed:
                print("landed and disarmed")
                return
    raise SystemExit("the mission did not end in time")


if __name__ == "__main__":
    raise SystemExit(main())
