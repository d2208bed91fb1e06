"""HIL_STATE_QUATERNION: the simulator's true state, which PX4 SITL streams for test harnesses (MAVSDK's ground_truth).

PX4's stream (src/modules/mavlink/streams/HIL_STATE_QUATERNION.hpp) reads SIH's groundtruth topics
(vehicle_attitude_groundtruth, vehicle_angular_velocity_groundtruth, vehicle_local_position_groundtruth,
vehicle_global_position_groundtruth), never the estimate: so here the builder reads the physics (Vehicle.ground_truth),
not the snapshot, and a fault that corrupts the estimate leaves it untouched. It is in PX4's stream list but in neither
default set of a SITL link (mavlink_main.cpp configure_streams_to_default; reference 1.5/1.6 and
../shared/reference/px4-gcs-streams.json), so it goes out only when a client asks: SET_MESSAGE_INTERVAL or
REQUEST_MESSAGE.

What PX4 puts on the wire, field by field: time_usec is left 0 (the stream never sets it); lat/lon in 1e-7 degrees and
alt in mm AMSL; velocities in cm/s; the airspeeds 0; and the accelerations are the local position's ax/ay/az in m/s^2
written unscaled into fields the message defines in mG. Each float goes into its integer field as C converts it,
truncated toward zero (saturated here where C's conversion would be undefined).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from sitl_emu.mavlink.context import EndpointContext, OutMessage
    from sitl_emu.types import VehicleSnapshot

INT16 = (-32768, 32767)
INT32 = (-2147483648, 2147483647)


def hil_state_quaternion(ctx: EndpointContext, snap: VehicleSnapshot) -> OutMessage | None:
    """The true state now; None for a vehicle without a simulator behind it (PX4 sends nothing before its groundtruth
    topics are advertised)."""
    truth = ctx.vehicle.ground_truth()
    if truth is None:
        return None
    wx, wy, wz = truth.rates_frd_rad_s
    vx, vy, vz = truth.vel_ned_m_s
    ax, ay, az = truth.acc_ned_m_s2
    return ctx.encoder.hil_state_quaternion_encode(
        0, truth.q_wxyz, wx, wy, wz,
        _c_int(truth.lat_deg * 1e7, INT32), _c_int(truth.lon_deg * 1e7, INT32), _c_int(truth.alt_amsl_m * 1e3, INT32),
        _c_int(vx * 1e2, INT16), _c_int(vy * 1e2, INT16), _c_int(vz * 1e2, INT16), 0, 0,
        _c_int(ax, INT16), _c_int(ay, INT16), _c_int(az, INT16))


def _c_int(x: float, bounds: tuple[int, int]) -> int:
    """A float stored in an integer field as C does it: truncated toward zero; NaN 0, saturated at the bounds."""
    if math.isnan(x):
        return 0
    low, high = bounds
    return low if x <= low else high if x >= high else int(x)
