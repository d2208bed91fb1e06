"""The fence in PX4's manual modes: joyfly limits the sticks it sends as the vehicle nears a side. Pure, no I/O.

In POSCTL and ALTCTL joyfly cannot move a setpoint: PX4 turns the sticks into the vehicle's motion. So before each
MANUAL_CONTROL goes out, the stick component that points out of the fence (the square of `--fence` around home, and
`--min-alt`/`--max-alt` above it) is limited to what still lets the vehicle stop inside. What the sticks mean is
PX4's (defaults of PX4 main, 2026; src/lib/sticks/Sticks.cpp, flight_mode_manager/tasks/...):

- every stick goes through PX4's deadzone (MAN_DEADZONE 0.1) and expo (0.6) in POSCTL; ALTCTL's tilt sticks do not;
- POSCTL (MPC_POS_MODE 4, StickAccelerationXY.cpp): the right stick, rotated by the heading, commands an acceleration
  of up to A = 2 x MPC_ACC_HOR (6 m/s^2) against a drag of A / MPC_VEL_MANUAL (0.6 1/s) x velocity, so a held stick
  s settles at s x MPC_VEL_MANUAL (10 m/s); releasing the whole stick brakes harder ("brake boost") and locks the
  position;
- ALTCTL (StickTiltXY.cpp): the stick tilts the vehicle, an acceleration of up to tan(MPC_MAN_TILT_MAX 35 deg) x g
  (6.9 m/s^2), with no drag and no position hold: a vehicle left alone drifts on;
- the throttle commands a climb rate, up to MPC_Z_VEL_MAX_UP (3 m/s) up and MPC_Z_VEL_MAX_DN (1.5 m/s) down, and
  its centre brakes at the full MPC_ACC_DOWN_MAX / MPC_ACC_UP_MAX and holds the altitude.

The rule (`allowed_speed`): towards a side, the vehicle may move at most as fast as it can still stop before that side
less a `buffer_m`, planning a deceleration of `brake_acc_m_s2` = MPC_ACC_HOR / 2 (1.5 m/s^2) after a reaction time
of `reaction_s` (0.7 s: the stream period, PX4's loops, the telemetry's age and the jerk-limited start of braking).
That is conservative against real PX4: released at 6 m/s in POSCTL, it stops within 10.5 m (the reference trace
p_fwd), where this rule plans for 16 m. The stick component towards the side is then set so the vehicle's measured
speed tracks that allowance (gain `track_gain_1_s`): it falls to 0 at the buffer and turns into a brake (a push
inwards) when the vehicle is faster than allowed; it never pushes further out than the pilot does. In POSCTL a
fully released stick is left alone (PX4's own brake and position lock are stronger); in ALTCTL, where nothing else
stops a drifting vehicle, the brake applies whatever the pilot does. Vertically, the throttle's climb (descent) is
limited to the allowance above (below) the vehicle, down to the centred throttle, which holds the altitude.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace

from joyfly.sticks.manual import ManualInput, from_throttle
from joyfly.sticks.setpoints import Fence, Vec3

G = 9.80665
STICK_EPS = 1e-6


@dataclass(frozen=True, slots=True)
class ManualModel:
    """What PX4 does with the sticks (its parameter defaults) and the braking joyfly plans with."""

    vel_manual_m_s: float = 10.0  # MPC_VEL_MANUAL
    acc_hor_m_s2: float = 3.0  # MPC_ACC_HOR
    tilt_max_deg: float = 35.0  # MPC_MAN_TILT_MAX
    z_vel_up_m_s: float = 3.0  # MPC_Z_VEL_MAX_UP
    z_vel_down_m_s: float = 1.5  # MPC_Z_VEL_MAX_DN
    deadzone: float = 0.1  # MAN_DEADZONE
    expo: float = 0.6  # the Sticks library's fixed expo (MPC_XY_MAN_EXPO / MPC_Z_MAN_EXPO's old default)
    brake_acc_m_s2: float = 1.5  # planned deceleration: MPC_ACC_HOR / 2
    reaction_s: float = 0.7
    buffer_m: float = 0.5  # where the vehicle stops, inside the fence
    track_gain_1_s: float = 2.0  # how fast the stick pulls the speed to the allowance
    return_gain_1_s: float = 1.0  # inside the buffer: back out of it at this many m/s per metre

    @property
    def pos_acc_m_s2(self) -> float:
        """POSCTL: acceleration at full stick (StickAccelerationXY: 2 x MPC_ACC_HOR, "drag halves the mean")."""
        return 2.0 * self.acc_hor_m_s2

    @property
    def pos_drag_1_s(self) -> float:
        return self.pos_acc_m_s2 / self.vel_manual_m_s

    @property
    def tilt_acc_m_s2(self) -> float:
        """ALTCTL: acceleration at full stick (StickTiltXY: tan(MPC_MAN_TILT_MAX) x g)."""
        return math.tan(math.radians(self.tilt_max_deg)) * G


PX4 = ManualModel()


# --- PX4's stick shaping (Sticks.cpp, mathlib Functions.hpp) and its inverse -------------------------------------

def px4_shape(s: float, m: ManualModel = PX4) -> float:
    """expo(deadzone(s)): the stick value PX4's POSCTL/ALTCTL flight tasks act on."""
    s = max(-1.0, min(1.0, s))
    dz = min(max(m.deadzone, 0.0), 0.99)
    d = 0.0 if abs(s) <= dz else math.copysign((abs(s) - dz) / (1.0 - dz), s)
    return (1.0 - m.expo) * d + m.expo * d ** 3


def px4_unshape(e: float, m: ManualModel = PX4) -> float:
    """The stick that PX4 shapes to `e` (0 for 0): the inverse of px4_shape, by bisection (it is monotonic)."""
    if abs(e) < STICK_EPS:
        return 0.0
    target = min(abs(e), 1.0)
    lo, hi = 0.0, 1.0
    for _ in range(40):
        mid = (lo + hi) / 2
        if (1.0 - m.expo) * mid + m.expo * mid ** 3 < target:
            lo = mid
        else:
            hi = mid
    dz = min(max(m.deadzone, 0.0), 0.99)
    return math.copysign(hi * (1.0 - dz) + dz, e)


# --- the braking rule -------------------------------------------------------------------------------------------

def stop_distance(speed_m_s: float, m: ManualModel = PX4) -> float:
    """How far the vehicle runs on, at most, once it starts to stop from `speed_m_s`."""
    v = max(speed_m_s, 0.0)
    return v * m.reaction_s + v * v / (2.0 * m.brake_acc_m_s2)


def allowed_speed(room_m: float, m: ManualModel = PX4) -> float:
    """The fastest the vehicle may move towards a side `room_m` away (it then stops `buffer_m` short of it);
    negative inside the buffer: move back out of it."""
    room = room_m - m.buffer_m
    if room <= 0.0:
        return room * m.return_gain_1_s
    a, t = m.brake_acc_m_s2, m.reaction_s
    return a * (-t + math.sqrt(t * t + 2.0 * room / a))


def _limit_axis(u: float, pos: float, vel: float, centre: float, half_width: float, acc: float, drag: float,
                m: ManualModel) -> float:
    """One world axis of the (shaped) stick, limited against both sides of the fence."""
    for side in (1.0, -1.0):
        room = (centre + side * half_width - pos) * side
        v_out = vel * side
        cap = (m.track_gain_1_s * (allowed_speed(room, m) - v_out) + drag * v_out) / acc
        if u * side > cap:
            u = cap * side
    return max(-1.0, min(1.0, u))


def _rotate(f: float, r: float, yaw: float) -> tuple[float, float]:
    """Body (forward, right) -> world (north, east), as PX4's rotateIntoHeadingFrameXY."""
    c, s = math.cos(yaw), math.sin(yaw)
    return c * f - s * r, s * f + c * r


def limit_horizontal(x: float, y: float, pos: Vec3, vel: Vec3, yaw: float, fence: Fence, altitude_mode: bool,
                     m: ManualModel = PX4) -> tuple[float, float]:
    """The right stick (x forward, y right, -1..1) limited by the fence's sides; unchanged when nothing binds."""
    if not fence.enabled:
        return x, y
    shape: Callable[[float], float] = (lambda s: s) if altitude_mode else (lambda s: px4_shape(s, m))
    north, east = _rotate(shape(x), shape(y), yaw)
    if not altitude_mode and abs(north) < STICK_EPS and abs(east) < STICK_EPS:
        return x, y  # POSCTL brakes harder and locks the position by itself when the stick is released
    acc, drag = (m.tilt_acc_m_s2, 0.0) if altitude_mode else (m.pos_acc_m_s2, m.pos_drag_1_s)
    hx, hy, _ = fence.home_ned_m
    n2 = _limit_axis(north, pos[0], vel[0], hx, fence.half_width_m, acc, drag, m)
    e2 = _limit_axis(east, pos[1], vel[1], hy, fence.half_width_m, acc, drag, m)
    if abs(n2 - north) < STICK_EPS and abs(e2 - east) < STICK_EPS:
        return x, y
    f, r = _rotate(n2, e2, -yaw)
    unshape: Callable[[float], float] = (lambda e: e) if altitude_mode else (lambda e: px4_unshape(e, m))
    return unshape(f), unshape(r)


def limit_throttle(throttle: float, alt_m: float, climb_m_s: float, fence: Fence, m: ManualModel = PX4) -> float:
    """The throttle (-1..1, 0 centred) limited so the climb stops below --max-alt and the descent above --min-alt;
    at or past a bound the throttle is centred (PX4 then holds the altitude)."""
    e = px4_shape(throttle, m)
    if e > 0.0:
        allowed = max(allowed_speed(fence.max_alt_m - alt_m, m), 0.0)
        cap = allowed / m.z_vel_up_m_s if climb_m_s <= allowed else 0.0
        if e > cap:
            return px4_unshape(cap, m)
    elif e < 0.0:
        allowed = max(allowed_speed(alt_m - fence.min_alt_m, m), 0.0)
        cap = allowed / m.z_vel_down_m_s if -climb_m_s <= allowed else 0.0
        if -e > cap:
            return -px4_unshape(cap, m)
    return throttle


def limit_manual(inp: ManualInput, pos: Vec3, vel: Vec3, yaw: float, fence: Fence, altitude_mode: bool,
                 m: ManualModel = PX4) -> ManualInput:
    """The MANUAL_CONTROL sticks limited by the fence (horizontal sides, altitude band); yaw passes unchanged."""
    x, y = limit_horizontal(inp.x / 1000, inp.y / 1000, pos, vel, yaw, fence, altitude_mode, m)
    throttle = limit_throttle(inp.throttle, fence.alt_m(pos), -vel[2], fence, m)
    out = replace(inp, x=round(x * 1000) if x != inp.x / 1000 else inp.x,
                  y=round(y * 1000) if y != inp.y / 1000 else inp.y)
    return replace(out, z=from_throttle(throttle)) if throttle != inp.throttle else out
