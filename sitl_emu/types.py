"""The vehicle's inputs and outputs: small frozen dataclasses, no MAVLink.

The MAVLink receiver turns messages into these inputs; the telemetry side turns `VehicleSnapshot`s and
`VehicleEvent`s into messages. NaN means "not controlled" throughout, as in PX4's uORB topics.
Frames: NED world, FRD body, quaternions w-first. Units are in the names.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Final

from sitl_emu.px4 import LandedState, NavState, Severity

Vec3 = tuple[float, float, float]
Vec4 = tuple[float, float, float, float]

NAN: Final = math.nan
NAN3: Vec3 = (NAN, NAN, NAN)


@dataclass(frozen=True, slots=True)
class OffboardControlMode:
    """PX4's offboard_control_mode: which setpoint kinds an offboard message carries (refreshes the 1 s watchdog)."""

    position: bool = False
    velocity: bool = False
    acceleration: bool = False
    attitude: bool = False
    body_rate: bool = False

    def any(self) -> bool:
        return self.position or self.velocity or self.acceleration or self.attitude or self.body_rate


@dataclass(slots=True)
class TrajectorySetpoint:
    """PX4's trajectory_setpoint in the local NED frame; NaN components are not controlled.

    Read-only by convention: one setpoint is held and shared (see ARCHITECTURE.md, On the tick path)."""

    position_ned_m: Vec3 = NAN3
    velocity_ned_m_s: Vec3 = NAN3
    acceleration_ned_m_s2: Vec3 = NAN3
    yaw_rad: float = NAN
    yawspeed_rad_s: float = NAN

    def __init__(self, position_ned_m: Vec3 = NAN3, velocity_ned_m_s: Vec3 = NAN3,
                 acceleration_ned_m_s2: Vec3 = NAN3, yaw_rad: float = NAN, yawspeed_rad_s: float = NAN) -> None:
        self.position_ned_m = position_ned_m
        self.velocity_ned_m_s = velocity_ned_m_s
        self.acceleration_ned_m_s2 = acceleration_ned_m_s2
        self.yaw_rad = yaw_rad
        self.yawspeed_rad_s = yawspeed_rad_s


@dataclass(frozen=True, slots=True)
class AttitudeSetpoint:
    """From SET_ATTITUDE_TARGET: attitude (q_wxyz, or None) and/or body rates, with body-frame thrust (0..1)."""

    q_wxyz: Vec4 | None = None
    body_rates_rad_s: Vec3 = NAN3
    thrust_body: Vec3 = (0.0, 0.0, 0.0)


@dataclass(frozen=True, slots=True)
class ManualControlSetpoint:
    """PX4's manual_control_setpoint from a MAVLink joystick (MANUAL_CONTROL): sticks in -1..1, throttle -1 (low)
    .. 1 (high), 0 the centre; `buttons` the bitfield as sent."""

    roll: float = 0.0
    pitch: float = 0.0
    yaw: float = 0.0
    throttle: float = -1.0
    buttons: int = 0


@dataclass(frozen=True, slots=True)
class VehicleCommand:
    """PX4's vehicle_command; `command` uses MAV_CMD numbering, as PX4 does internally."""

    command: int
    params: tuple[float, float, float, float, float, float, float] = (NAN,) * 7  # type: ignore[assignment]
    source_system: int = 255
    source_component: int = 190
    from_external: bool = True  # False for the pxh> shell ("Armed by internal command")

    def param(self, i: int) -> float:
        """1-based, as MAVLink names them: param(1) is param1."""
        return self.params[i - 1]


@dataclass(frozen=True, slots=True)
class CommandAck:
    command: int
    result: int  # MavResult


@dataclass(frozen=True, slots=True)
class VehicleEvent:
    """A message PX4 would log: a console line and, where PX4 does, a STATUSTEXT.

    `text` has no trailing tab; `is_event` True means PX4 also emits it as an event, so its STATUSTEXT ends in '\\t'.
    `seq` increases by one per event from boot.
    """

    seq: int
    time_us: int
    severity: Severity
    module: str  # 'commander', 'navigator', ...
    text: str
    is_event: bool = True
    statustext: bool = True  # False: console only

    @property
    def statustext_text(self) -> str:
        return self.text + ("\t" if self.is_event else "")

    @property
    def console_line(self) -> str:
        level = {Severity.INFO: "INFO", Severity.WARNING: "WARN", Severity.CRITICAL: "ERROR",
                 Severity.ERROR: "ERROR", Severity.EMERGENCY: "PANIC"}.get(self.severity, "INFO")
        # a text that names its module itself (the logger's "[logger] ./log/...ulg") gets the prefix once
        return f"{level:<5} [{self.module}] {self.text.removeprefix(f'[{self.module}] ')}"


@dataclass(frozen=True, slots=True)
class HomePosition:
    lat_deg: float
    lon_deg: float
    alt_amsl_m: float
    pos_ned_m: Vec3
    yaw_rad: float


@dataclass(frozen=True, slots=True)
class GroundTruth:
    """The physics' true state, not the estimate: what PX4's SIH publishes as its vehicle_*_groundtruth topics
    (simulator_sih/sih.cpp publish_ground_truth) and HIL_STATE_QUATERNION streams."""

    pos_ned_m: Vec3
    vel_ned_m_s: Vec3
    acc_ned_m_s2: Vec3
    q_wxyz: Vec4
    rates_frd_rad_s: Vec3
    lat_deg: float
    lon_deg: float
    alt_amsl_m: float


@dataclass(frozen=True, slots=True)
class OrbitStatus:
    """PX4's orbit_status while the orbit flight task runs (ORBIT_EXECUTION_STATUS): the signed radius (positive
    clockwise), the centre and the altitude (AMSL) of the altitude setpoint."""

    time_us: int
    radius_m: float
    lat_deg: float
    lon_deg: float
    alt_amsl_m: float
    yaw_behaviour: int


@dataclass(frozen=True, slots=True)
class FollowTargetSample:
    """FOLLOW_TARGET as PX4's follow_target topic holds it: where the target is (WGS84, AMSL) and its NED velocity,
    stamped with the vehicle's time of receipt."""

    time_us: int
    lat_deg: float
    lon_deg: float
    alt_amsl_m: float
    vel_ned_m_s: Vec3


@dataclass(slots=True)
class VehicleSnapshot:
    """Everything telemetry needs, at one instant of simulated time (Vehicle.snapshot, cached until the next step
    or input). Read-only by convention (see ARCHITECTURE.md, On the tick path)."""

    time_us: int
    # state machine
    armed: bool
    nav_state: NavState
    user_intended_nav_state: NavState
    failsafe: bool
    landed_state: LandedState
    pre_flight_checks_pass: bool  # arming checks pass for the current nav_state (system_status STANDBY)
    position_valid: bool  # estimator has local + global position (SYS_STATUS GPS / local pos health)
    takeoff_detected: bool
    offboard_control: OffboardControlMode | None  # last offboard signal kinds (for base_mode in OFFBOARD)
    # estimate (local frame origin = ref lat/lon/alt)
    pos_ned_m: Vec3
    vel_ned_m_s: Vec3
    acc_ned_m_s2: Vec3
    q_wxyz: Vec4
    rates_frd_rad_s: Vec3
    euler_rad: Vec3  # roll, pitch, yaw
    lat_deg: float
    lon_deg: float
    alt_amsl_m: float
    ref_lat_deg: float
    ref_lon_deg: float
    ref_alt_amsl_m: float
    home: HomePosition | None
    # controller internals, for POSITION_TARGET_LOCAL_NED / ATTITUDE_TARGET / VFR_HUD
    local_setpoint: TrajectorySetpoint | None
    attitude_setpoint_q_wxyz: Vec4 | None
    rates_setpoint_rad_s: Vec3
    thrust_setpoint: float  # collective, 0..1
    motors: Vec4  # 0..1, the motors' state (SIH's first-order lag behind the commands)
    # battery
    battery_voltage_v: float = 16.2
    battery_remaining: float = 1.0  # 0..1
    extras: dict[str, float] = field(default_factory=dict)
    # actuators: the mixer's commands this tick (PX4's actuator_motors), 0..1; SERVO_OUTPUT_RAW and the outputs
    motor_commands: Vec4 = (0.0, 0.0, 0.0, 0.0)
    # the kinds of the last offboard message since boot, fresh or not: PX4's commander derives OFFBOARD's control
    # mode from the last offboard_control_mode it received (HEARTBEAT base_mode), whatever its age
    offboard_control_last: OffboardControlMode | None = None
    manual_control: bool = False  # a manual input (MAVLink joystick) is present: SYS_STATUS's RC receiver
    battery_warning: int = 0  # battery_status_s::WARNING_* (0 none, 1 low, 2 critical, 3 emergency)
    gps_fix_type: int = 3  # SIH's GPS: 3D fix; 0 while a GPS failure is injected
    orbit: OrbitStatus | None = None  # while the orbit flight task runs (ORBIT_EXECUTION_STATUS)

    def __init__(self, time_us: int, armed: bool, nav_state: NavState, user_intended_nav_state: NavState,
                 failsafe: bool, landed_state: LandedState, pre_flight_checks_pass: bool, position_valid: bool,
                 takeoff_detected: bool, offboard_control: OffboardControlMode | None, pos_ned_m: Vec3,
                 vel_ned_m_s: Vec3, acc_ned_m_s2: Vec3, q_wxyz: Vec4, rates_frd_rad_s: Vec3, euler_rad: Vec3,
                 lat_deg: float, lon_deg: float, alt_amsl_m: float, ref_lat_deg: float, ref_lon_deg: float,
                 ref_alt_amsl_m: float, home: HomePosition | None, local_setpoint: TrajectorySetpoint | None,
                 attitude_setpoint_q_wxyz: Vec4 | None, rates_setpoint_rad_s: Vec3, thrust_setpoint: float,
                 motors: Vec4, battery_voltage_v: float = 16.2, battery_remaining: float = 1.0,
                 extras: dict[str, float] | None = None, motor_commands: Vec4 = (0.0, 0.0, 0.0, 0.0),
                 offboard_control_last: OffboardControlMode | None = None, manual_control: bool = False,
                 battery_warning: int = 0, gps_fix_type: int = 3, orbit: OrbitStatus | None = None) -> None:
        self.time_us = time_us
        self.armed = armed
        self.nav_state = nav_state
        self.user_intended_nav_state = user_intended_nav_state
        self.failsafe = failsafe
        self.landed_state = landed_state
        self.pre_flight_checks_pass = pre_flight_checks_pass
        self.position_valid = position_valid
        self.takeoff_detected = takeoff_detected
        self.offboard_control = offboard_control
        self.pos_ned_m = pos_ned_m
        self.vel_ned_m_s = vel_ned_m_s
        self.acc_ned_m_s2 = acc_ned_m_s2
        self.q_wxyz = q_wxyz
        self.rates_frd_rad_s = rates_frd_rad_s
        self.euler_rad = euler_rad
        self.lat_deg = lat_deg
        self.lon_deg = lon_deg
        self.alt_amsl_m = alt_amsl_m
        self.ref_lat_deg = ref_lat_deg
        self.ref_lon_deg = ref_lon_deg
        self.ref_alt_amsl_m = ref_alt_amsl_m
        self.home = home
        self.local_setpoint = local_setpoint
        self.attitude_setpoint_q_wxyz = attitude_setpoint_q_wxyz
        self.rates_setpoint_rad_s = rates_setpoint_rad_s
        self.thrust_setpoint = thrust_setpoint
        self.motors = motors
        self.battery_voltage_v = battery_voltage_v
        self.battery_remaining = battery_remaining
        self.extras = {} if extras is None else extras
        self.motor_commands = motor_commands
        self.offboard_control_last = offboard_control_last
        self.manual_control = manual_control
        self.battery_warning = battery_warning
        self.gps_fix_type = gps_fix_type
        self.orbit = orbit
