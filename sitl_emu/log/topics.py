"""The uORB topics a flight log holds: PX4's names, fields and logging rates, their values from the vehicle.

Field lists (names, C types, order and padding) are those of a ULog written by PX4 SITL+SIH (the shape of PX4's
msg/*.msg once its message generator has sorted the fields by size; ../shared/reference/px4-ulog-topics.txt),
manual_control_setpoint's from msg/versioned/ManualControlSetpoint.msg. Fields sitl_emu does not model stay zero,
as in PX4's zero-initialised structs.

Rates: src/modules/logger/logged_topics.cpp add_default_topics() gives each topic its least interval (ms); PX4 SITL
runs SDLOG_PROFILE 131 (ROMFS/px4fmu_common/init.d-posix/rcS: default + estimator replay + vision), whose replay set
logs vehicle_attitude, vehicle_local_position and vehicle_global_position at every update and
vehicle_angular_velocity every 10 ms. Every update here means PX4's publication rate: vehicle_attitude every 4 ms
tick, the local and global position at the EKF's ~125 Hz (8 ms; the reference log: 124.9 and 120.6 Hz).
Topics PX4 publishes on change (vehicle_status, vehicle_land_detected, home_position, offboard_control_mode) are
written when their state changes and at PX4's publication period.

Each topic's values are a flat tuple, in the order of the field names its `@fields(...)` line gives, an array's
elements in its place (t, t, *q); the other fields keep the format's defaults (CONSTANTS). The topics logged at
high rate, and the states watched every tick (flight_log.py), read the vehicle's estimate and the commander's
fields; the controllers' setpoints and outputs come from the vehicle snapshot, which is only taken on a tick where
such a topic is due (Inputs.snap).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Hashable
from dataclasses import dataclass
from typing import Any, Final

from sitl_emu.control.qmath import yaw_from_q
from sitl_emu.geo import ned_to_global
from sitl_emu.log.ulog_writer import MessageFormat
from sitl_emu.mavlink.telemetry.actuators import servo_outputs
from sitl_emu.physics import RigidBodyState
from sitl_emu.px4 import LandedState, NavState
from sitl_emu.types import ManualControlSetpoint, VehicleSnapshot
from sitl_emu.vehicle.vehicle import Vehicle

NAN: Final = math.nan
INF: Final = math.inf
EPH_M: Final = 0.3  # a valid estimate's accuracies: horizontal and vertical position, velocity (EKF2 in SITL)
EPV_M: Final = 0.4
EV_M_S: Final = 0.1
INVALID_ACCURACY_M: Final = 1e3
ARMING_STATE_DISARMED: Final = 1  # msg/VehicleStatus.msg
ARMING_STATE_ARMED: Final = 2
VEHICLE_TYPE_ROTARY_WING: Final = 1
MAV_TYPE_QUADROTOR: Final = 2
BATTERY_CELLS: Final = 4  # BAT1_N_CELLS in PX4 SITL
SOURCE_MAVLINK_0: Final = 2  # manual_control_setpoint.data_source of a MAVLink joystick on mavlink instance 0
ACTUATOR_CONTROLS: Final = 12  # actuator_motors.control
PWM_OUTPUTS: Final = 16

Values = dict[str, Any]
Row = tuple[Any, ...]  # a topic's values, in the order of its field names, arrays spread into their elements


class Inputs:
    """What the topics read at one tick: the time, the vehicle's estimate and the vehicle (cheap fields), and the
    snapshot, taken on first use in a tick (`snap`) by `take_snapshot`."""

    __slots__ = ("_snap", "_take_snapshot", "estimate", "sysid", "time_us", "vehicle")

    def __init__(self, vehicle: Vehicle, sysid: int, take_snapshot: Callable[[], VehicleSnapshot]) -> None:
        self.vehicle = vehicle
        self.sysid = sysid
        self._take_snapshot = take_snapshot
        self.new_tick()

    def new_tick(self) -> None:
        """The vehicle stepped: read its time and estimate again, and forget the snapshot."""
        self.time_us: int = self.vehicle.time_us
        self.estimate: RigidBodyState = self.vehicle.estimate
        self._snap: VehicleSnapshot | None = None

    @property
    def snap(self) -> VehicleSnapshot:
        if self._snap is None:
            self._snap = self._take_snapshot()
        return self._snap


@dataclass(frozen=True, slots=True)
class Fields:
    """How a topic's values are read: `read(inputs)` gives the values of the fields `names` (a flat Row; None:
    nothing published now)."""

    names: tuple[str, ...]
    read: Callable[[Inputs], Row | None]


def fields(*names: str) -> Callable[[Callable[[Inputs], Row | None]], Fields]:
    """Decorates a topic's value function with the names of the fields its tuple fills."""
    return lambda read: Fields(names, read)


@dataclass(frozen=True, slots=True)
class Topic:
    format: MessageFormat  # with the topic's constant fields as its defaults
    interval_us: int  # at most one message per interval (0: every tick)
    values: Fields  # the fields it sets and how they are read
    state: Callable[[Inputs], Hashable] | None = None  # a change is written at once (cheap reads: every tick)

    @property
    def name(self) -> str:
        return self.format.name


def _thrust_body(snap: VehicleSnapshot) -> tuple[float, float, float]:
    return (0.0, 0.0, -snap.thrust_setpoint)


@fields("timestamp", "timestamp_sample", "q")
def _attitude(i: Inputs) -> Row:
    t = i.time_us
    w, x, y, z = i.estimate.q_wxyz
    return t, t, w, x, y, z


@fields("timestamp", "timestamp_sample", "xyz")
def _angular_velocity(i: Inputs) -> Row:
    t = i.time_us
    roll, pitch, yaw = i.estimate.rates_frd_rad_s
    return t, t, roll, pitch, yaw


@fields("timestamp", "timestamp_sample", "ref_lat", "ref_lon", "x", "y", "z", "vx", "vy", "vz", "z_deriv", "ax", "ay",
        "az", "heading", "ref_alt", "dist_bottom", "eph", "epv", "evh", "evv", "vxy_max", "vz_max", "hagl_min",
        "hagl_max_z", "hagl_max_xy", "xy_valid", "z_valid", "v_xy_valid", "v_z_valid", "heading_good_for_control",
        "xy_global", "z_global", "dist_bottom_valid")
def _local_position(i: Inputs) -> Row:
    t, e, ref = i.time_us, i.estimate, i.vehicle.ref
    x, y, z = e.pos_ned_m  # (one vector a statement: compiled, a tuple of them is built and iterated)
    vx, vy, vz = e.vel_ned_m_s
    ax, ay, az = e.acc_ned_m_s2
    ok = i.vehicle.position_valid()
    return (t, t, ref.lat_deg, ref.lon_deg, x, y, z, vx, vy, vz, vz, ax, ay, az,
            yaw_from_q(e.q_wxyz), ref.alt_amsl_m, -z, EPH_M if ok else INVALID_ACCURACY_M,
            EPV_M if ok else INVALID_ACCURACY_M, EV_M_S, EV_M_S, INF, INF, INF, INF, INF,  # (no speed or height limits)
            ok, ok, ok, ok, ok, ok, ok, ok)  # the valid and global flags


@fields("timestamp", "timestamp_sample", "lat", "lon", "alt", "alt_ellipsoid", "eph", "epv", "lat_lon_valid",
        "alt_valid")
def _global_position(i: Inputs) -> Row | None:
    if not i.vehicle.position_valid():
        return None
    t = i.time_us
    lat, lon, alt = ned_to_global(i.vehicle.ref, i.estimate.pos_ned_m)
    return t, t, lat, lon, alt, alt, EPH_M, EPV_M, True, True


@fields("timestamp", "x", "y", "z", "vx", "vy", "vz", "acceleration", "thrust", "yaw", "yawspeed")
def _local_setpoint(i: Inputs) -> Row | None:
    s, sp = i.snap, i.snap.local_setpoint
    if sp is None:
        return None
    x, y, z = sp.position_ned_m
    vx, vy, vz = sp.velocity_ned_m_s
    ax, ay, az = sp.acceleration_ned_m_s2
    tx, ty, tz = _thrust_body(s)
    return s.time_us, x, y, z, vx, vy, vz, ax, ay, az, tx, ty, tz, sp.yaw_rad, sp.yawspeed_rad_s


@fields("timestamp", "position", "velocity", "acceleration", "jerk", "yaw", "yawspeed")
def _trajectory_setpoint(i: Inputs) -> Row | None:
    s, sp = i.snap, i.snap.local_setpoint
    if sp is None:
        return None
    x, y, z = sp.position_ned_m
    vx, vy, vz = sp.velocity_ned_m_s
    ax, ay, az = sp.acceleration_ned_m_s2
    return s.time_us, x, y, z, vx, vy, vz, ax, ay, az, NAN, NAN, NAN, sp.yaw_rad, sp.yawspeed_rad_s  # (no jerk)


@fields("timestamp", "q_d", "thrust_body")
def _attitude_setpoint(i: Inputs) -> Row | None:
    s = i.snap
    q = s.attitude_setpoint_q_wxyz
    if q is None or not s.armed:
        return None
    w, x, y, z = q
    tx, ty, tz = _thrust_body(s)
    return s.time_us, w, x, y, z, tx, ty, tz


@fields("timestamp", "roll", "pitch", "yaw", "thrust_body")
def _rates_setpoint(i: Inputs) -> Row | None:
    if not i.vehicle.commander.armed:
        return None
    s = i.snap
    roll, pitch, yaw = s.rates_setpoint_rad_s
    tx, ty, tz = _thrust_body(s)
    return s.time_us, roll, pitch, yaw, tx, ty, tz


@fields("timestamp", "timestamp_sample", "xyz")
def _thrust_setpoint(i: Inputs) -> Row | None:
    if not i.vehicle.commander.armed:
        return None
    s = i.snap
    tx, ty, tz = _thrust_body(s)
    return s.time_us, s.time_us, tx, ty, tz


@fields("timestamp", "timestamp_sample", "control")
def _actuator_motors(i: Inputs) -> Row:
    s = i.snap
    unused = (NAN,) * (ACTUATOR_CONTROLS - len(s.motor_commands))
    return s.time_us, s.time_us, *s.motor_commands, *unused


@fields("timestamp", "output")
def _actuator_outputs(i: Inputs) -> Row:
    return i.snap.time_us, *(float(v) for v in servo_outputs(i.snap))


@fields("timestamp", "voltage_v", "remaining", "voltage_cell_v")
def _battery(i: Inputs) -> Row:
    battery = i.vehicle.faults.battery
    cells = (battery.voltage_v / BATTERY_CELLS,) * BATTERY_CELLS + (0.0,) * (14 - BATTERY_CELLS)
    return i.time_us, battery.voltage_v, battery.remaining, *cells


def _status_state(i: Inputs) -> tuple[bool, NavState, NavState, bool, bool]:
    """(armed, nav_state, user-intended nav_state, failsafe, pre-flight checks pass), from the commander."""
    c = i.vehicle.commander
    return c.armed, c.nav_state, c.intention.user_intended, c.failsafe, c.pre_flight_checks_pass()


@fields("timestamp", "arming_state", "nav_state_user_intention", "nav_state", "nav_state_display", "failsafe",
        "system_id", "accepts_offboard_setpoints", "pre_flight_checks_pass")
def _status(i: Inputs) -> Row:
    armed, nav_state, intended, failsafe, checks_pass = _status_state(i)
    return (i.time_us, ARMING_STATE_ARMED if armed else ARMING_STATE_DISARMED, int(intended), int(nav_state),
            int(nav_state), failsafe, i.sysid, nav_state is NavState.OFFBOARD, checks_pass)


def _landed_state(i: Inputs) -> LandedState:
    return i.vehicle.landed_state()


@fields("timestamp", "ground_contact", "maybe_landed", "landed", "in_descend", "has_low_throttle",
        "close_to_ground_or_skipped_check", "at_rest")
def _land_detected(i: Inputs) -> Row:
    landed_state = _landed_state(i)
    landed = landed_state is LandedState.ON_GROUND
    return (i.time_us, landed, landed, landed, landed_state is LandedState.LANDING, landed,
            landed or -i.estimate.pos_ned_m[2] < 1.0, landed)


def _home_state(i: Inputs) -> Hashable:
    return i.vehicle.commander.home


@fields("timestamp", "lat", "lon", "alt", "x", "y", "z", "yaw")
def _home(i: Inputs) -> Row | None:
    h = i.vehicle.commander.home
    if h is None:
        return None
    x, y, z = h.pos_ned_m
    return i.time_us, h.lat_deg, h.lon_deg, h.alt_amsl_m, x, y, z, h.yaw_rad


@fields("timestamp", "timestamp_sample", "roll", "pitch", "yaw", "throttle", "buttons")
def _manual(i: Inputs) -> Row | None:
    """The last sticks while manual control is valid (the commander's COM_RC_LOSS_T watchdog)."""
    c, t = i.vehicle.commander, i.time_us
    if not c.manual_control_valid(t):
        return None
    m: ManualControlSetpoint = c.manual.setpoint
    return t, t, m.roll, m.pitch, m.yaw, m.throttle, m.buttons


def _offboard_state(i: Inputs) -> Hashable:
    return i.vehicle.commander.offboard_mode_last


@fields("timestamp", "position", "velocity", "acceleration", "attitude", "body_rate")
def _offboard_mode(i: Inputs) -> Row | None:
    m = i.vehicle.commander.offboard_mode_last
    if m is None:
        return None
    return i.time_us, m.position, m.velocity, m.acceleration, m.attitude, m.body_rate


SPECS = {
    "vehicle_attitude": "uint64_t timestamp;uint64_t timestamp_sample;float[4] q;float[4] delta_q_reset;"
                        "uint8_t quat_reset_counter;uint8_t[7] _padding0",
    "vehicle_angular_velocity": "uint64_t timestamp;uint64_t timestamp_sample;float[3] xyz;float[3] xyz_derivative",
    "vehicle_local_position":
        "uint64_t timestamp;uint64_t timestamp_sample;uint64_t ref_timestamp;double ref_lat;double ref_lon;float x;"
        "float y;float z;float[2] delta_xy;float delta_z;float vx;float vy;float vz;float z_deriv;float[2] delta_vxy;"
        "float delta_vz;float ax;float ay;float az;float heading;float heading_var;float unaided_heading;"
        "float delta_heading;float tilt_var;float ref_alt;float dist_bottom;float dist_bottom_var;"
        "float delta_dist_bottom;float eph;float epv;float evh;float evv;float vxy_max;float vz_max;float hagl_min;"
        "float hagl_max_z;float hagl_max_xy;bool xy_valid;bool z_valid;bool v_xy_valid;bool v_z_valid;"
        "uint8_t xy_reset_counter;uint8_t z_reset_counter;uint8_t vxy_reset_counter;uint8_t vz_reset_counter;"
        "uint8_t heading_reset_counter;bool heading_good_for_control;bool xy_global;bool z_global;"
        "bool dist_bottom_valid;uint8_t dist_bottom_reset_counter;uint8_t dist_bottom_sensor_bitfield;"
        "bool dead_reckoning",
    "vehicle_global_position":
        "uint64_t timestamp;uint64_t timestamp_sample;double lat;double lon;float alt;float alt_ellipsoid;"
        "float delta_alt;float delta_terrain;float eph;float epv;float terrain_alt;bool lat_lon_valid;bool alt_valid;"
        "uint8_t lat_lon_reset_counter;uint8_t alt_reset_counter;uint8_t terrain_reset_counter;"
        "bool terrain_alt_valid;bool dead_reckoning;uint8_t[5] _padding0",
    "vehicle_local_position_setpoint": "uint64_t timestamp;float x;float y;float z;float vx;float vy;float vz;"
                                       "float[3] acceleration;float[3] thrust;float yaw;float yawspeed",
    "trajectory_setpoint": "uint64_t timestamp;float[3] position;float[3] velocity;float[3] acceleration;"
                           "float[3] jerk;float yaw;float yawspeed",
    "vehicle_attitude_setpoint": "uint64_t timestamp;float yaw_sp_move_rate;float[4] q_d;float[3] thrust_body",
    "vehicle_rates_setpoint": "uint64_t timestamp;float roll;float pitch;float yaw;float[3] thrust_body;"
                              "bool reset_integral;uint8_t[7] _padding0",
    "vehicle_thrust_setpoint": "uint64_t timestamp;uint64_t timestamp_sample;float[3] xyz;uint8_t[4] _padding0",
    "actuator_motors": "uint64_t timestamp;uint64_t timestamp_sample;float[12] control;uint16_t reversible_flags;"
                       "uint8_t[6] _padding0",
    "actuator_outputs": "uint64_t timestamp;uint32_t noutputs;float[16] output;uint8_t[4] _padding0",
    "battery_status":
        "uint64_t timestamp;float voltage_v;float current_a;float current_average_a;float discharged_mah;"
        "float remaining;float scale;float time_remaining_s;float temperature;float[14] voltage_cell_v;"
        "float max_cell_voltage_delta;float full_charge_capacity_wh;float remaining_capacity_wh;"
        "float nominal_voltage;float internal_resistance_estimate;float ocv_estimate;float ocv_estimate_filtered;"
        "float volt_based_soc_estimate;float voltage_prediction;float prediction_error;"
        "float estimation_covariance_norm;uint16_t capacity;uint16_t cycle_count;uint16_t average_time_to_empty;"
        "uint16_t manufacture_date;uint16_t state_of_health;uint16_t max_error;uint16_t interface_error;"
        "uint16_t faults;uint16_t over_discharge_count;bool connected;uint8_t cell_count;uint8_t source;"
        "uint8_t priority;uint8_t id;bool is_powering_off;bool is_required;uint8_t warning;uint8_t[2] _padding0",
    "vehicle_status":
        "uint64_t timestamp;uint64_t armed_time;uint64_t takeoff_time;uint64_t nav_state_timestamp;"
        "uint32_t valid_nav_states_mask;uint32_t can_set_nav_states_mask;uint8_t arming_state;"
        "uint8_t latest_arming_reason;uint8_t latest_disarming_reason;uint8_t nav_state_user_intention;"
        "uint8_t nav_state;uint8_t executor_in_charge;uint8_t nav_state_display;bool accepts_offboard_setpoints;"
        "uint8_t hil_state;uint8_t vehicle_type;bool failsafe;bool failsafe_and_user_took_over;"
        "uint8_t failsafe_defer_state;bool gcs_connection_lost;uint8_t gcs_connection_lost_counter;"
        "bool high_latency_data_link_lost;bool is_vtol;bool is_vtol_tailsitter;bool in_transition_mode;"
        "bool in_transition_to_fw;uint8_t system_type;uint8_t system_id;uint8_t component_id;"
        "bool safety_button_available;bool safety_off;bool power_input_valid;bool usb_connected;"
        "bool open_drone_id_system_present;bool open_drone_id_system_healthy;bool parachute_system_present;"
        "bool parachute_system_healthy;bool traffic_avoidance_system_present;bool rc_calibration_in_progress;"
        "bool calibration_enabled;bool pre_flight_checks_pass;uint8_t[5] _padding0",
    "vehicle_land_detected": "uint64_t timestamp;bool freefall;bool ground_contact;bool maybe_landed;bool landed;"
                             "bool in_ground_effect;bool in_descend;bool has_low_throttle;bool vertical_movement;"
                             "bool horizontal_movement;bool rotational_movement;bool close_to_ground_or_skipped_check;"
                             "bool at_rest;uint8_t[4] _padding0",
    "home_position": "uint64_t timestamp;double lat;double lon;float alt;float x;float y;float z;float roll;"
                     "float pitch;float yaw;uint32_t update_count;bool valid_alt;bool valid_hpos;bool valid_lpos;"
                     "bool valid_attitude;bool manual_home;uint8_t[3] _padding0",
    "manual_control_setpoint": "uint64_t timestamp;uint64_t timestamp_sample;float roll;float pitch;float yaw;"
                               "float throttle;float flaps;float aux1;float aux2;float aux3;float aux4;float aux5;"
                               "float aux6;uint16_t buttons;bool valid;uint8_t data_source;bool sticks_moving;"
                               "uint8_t[7] _padding0",
    "offboard_control_mode": "uint64_t timestamp;bool position;bool velocity;bool acceleration;bool attitude;"
                             "bool body_rate;bool thrust_and_torque;bool direct_actuator;uint8_t[1] _padding0",
}

MS: Final = 1000
# name: (least interval in µs, values, state written on change or None) -- logged_topics.cpp's intervals
_TABLE: dict[str, tuple[int, Fields, Callable[[Inputs], Hashable] | None]] = {
    "vehicle_attitude": (0, _attitude, None),
    "vehicle_angular_velocity": (10 * MS, _angular_velocity, None),
    "vehicle_local_position": (8 * MS, _local_position, None),
    "vehicle_global_position": (8 * MS, _global_position, None),
    "vehicle_local_position_setpoint": (100 * MS, _local_setpoint, None),
    "trajectory_setpoint": (200 * MS, _trajectory_setpoint, None),
    "vehicle_attitude_setpoint": (50 * MS, _attitude_setpoint, None),
    "vehicle_rates_setpoint": (20 * MS, _rates_setpoint, None),
    "vehicle_thrust_setpoint": (20 * MS, _thrust_setpoint, None),
    "actuator_motors": (100 * MS, _actuator_motors, None),
    "actuator_outputs": (100 * MS, _actuator_outputs, None),
    "battery_status": (200 * MS, _battery, None),
    # published at 2 Hz or at once on a change (Commander.cpp); land_detected on change and at 1 Hz
    "vehicle_status": (500 * MS, _status, _status_state),
    "vehicle_land_detected": (1000 * MS, _land_detected, _landed_state),
    "home_position": (1000 * MS, _home, _home_state),
    "manual_control_setpoint": (200 * MS, _manual, None),
    "offboard_control_mode": (100 * MS, _offboard_mode, _offboard_state),
}


# fields that never change, set once as the format's defaults (the topics logged at every update give theirs in
# their rows instead, so that their messages are packed without gathering: ulog_writer.DataPacker)
CONSTANTS: dict[str, Values] = {
    "actuator_outputs": {"noutputs": PWM_OUTPUTS},
    "battery_status": {"scale": 1.0, "time_remaining_s": NAN, "temperature": NAN, "connected": True,
                       "cell_count": BATTERY_CELLS, "id": 1},
    "vehicle_status": {"vehicle_type": VEHICLE_TYPE_ROTARY_WING, "system_type": MAV_TYPE_QUADROTOR,
                       "component_id": 1, "power_input_valid": True},
    "home_position": {"valid_alt": True, "valid_hpos": True, "valid_lpos": True},
    "manual_control_setpoint": {"valid": True, "data_source": SOURCE_MAVLINK_0},
}


def default_topics() -> list[Topic]:
    """Every topic a flight log holds, in a fixed order (their msg_ids)."""
    topics = []
    for name, (interval, values, state) in _TABLE.items():
        fmt = MessageFormat(name, SPECS[name])
        fmt.set_defaults(CONSTANTS.get(name, {}))
        topics.append(Topic(fmt, interval, values, state))
    return topics
