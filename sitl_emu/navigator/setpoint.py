"""What the navigator and the flight tasks share: the vehicle's state as they read it, and the kind of setpoint.

`NavInput` bundles what PX4's navigator and FlightTasks subscribe to (vehicle_local_position, home_position,
vehicle_land_detected, takeoff_status, the position controller's last velocity setpoint); `SetpointType` is
position_setpoint.type (msg/PositionSetpoint.msg: IDLE, POSITION, TAKEOFF, LAND) plus what else may drive the
controllers (the offboard stream, nothing). The navigator's mission progression (mission.py) and every flight task
(sitl_emu/flight_tasks/) take them; the vehicle builds a NavInput each tick.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

from sitl_emu.control.takeoff import TakeoffState
from sitl_emu.geo import SIH_HOME
from sitl_emu.types import NAN, Vec3

NO_FEEDFORWARD: Vec3 = (NAN, NAN, NAN)


class SetpointType(Enum):
    """What drives the controllers: a navigator position_setpoint.type (IDLE, POSITION, TAKEOFF, LAND), the offboard
    stream, or nothing (manual and termination modes, disarmed)."""

    IDLE = "idle"
    POSITION = "position"
    TAKEOFF = "takeoff"
    LAND = "land"
    OFFBOARD = "offboard"
    NONE = "none"


@dataclass(slots=True)
class NavInput:
    """What the navigator and the flight tasks see of the vehicle, in the local NED frame (z = 0 is the ground at home).

    `takeoff_state` is the control cascade's TakeoffHandling state: while it is before the ramp (disarmed, spoolup,
    ready for takeoff) the trajectory is held at the vehicle, as PX4's FlightModeManager does; the default FLIGHT
    disables that. `ref_alt_amsl_m` is the AMSL altitude of the local origin (only used for the RTL message, which
    PX4 prints in AMSL). Made every tick; read-only by convention (see ARCHITECTURE.md, On the tick path).
    """

    time_us: int
    pos_ned_m: Vec3
    vel_ned_m_s: Vec3
    yaw_rad: float
    home_ned_m: Vec3
    home_yaw_rad: float
    landed: bool
    armed: bool
    takeoff_state: TakeoffState = TakeoffState.FLIGHT
    ref_alt_amsl_m: float = SIH_HOME[2]
    vel_sp_ned_m_s: Vec3 = NO_FEEDFORWARD  # the position controller's last velocity setpoint (NaN: none)

    def __init__(self, time_us: int, pos_ned_m: Vec3, vel_ned_m_s: Vec3, yaw_rad: float, home_ned_m: Vec3,
                 home_yaw_rad: float, landed: bool, armed: bool, takeoff_state: TakeoffState = TakeoffState.FLIGHT,
                 ref_alt_amsl_m: float = SIH_HOME[2], vel_sp_ned_m_s: Vec3 = NO_FEEDFORWARD) -> None:
        self.time_us = time_us
        self.pos_ned_m = pos_ned_m
        self.vel_ned_m_s = vel_ned_m_s
        self.yaw_rad = yaw_rad
        self.home_ned_m = home_ned_m
        self.home_yaw_rad = home_yaw_rad
        self.landed = landed
        self.armed = armed
        self.takeoff_state = takeoff_state
        self.ref_alt_amsl_m = ref_alt_amsl_m
        self.vel_sp_ned_m_s = vel_sp_ned_m_s
