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
of `reaction_s` (1.2 s: the stream period, PX4's loops, the telemetry's age, the jerk-limited start of braking and
the vehicle lagging its velocity setpoint). That is conservative against real PX4: released at 6 m/s in POSCTL, it
stops within 10.5 m (the reference trace p_fwd), where this rule plans for 19 m; a model of PX4's stick dynamics
with the vehicle lagging twice as much as PX4 did still stops inside (tests/joyfly/sticks/test_manual_fence.py).
The stick component towards the side is then set so the vehicle's speed tracks that allowance (gain
`track_gain_1_s`): it falls to 0 at the buffer and turns into a brake (a push inwards) when the vehicle is faster
than allowed; it never pushes further out than the pilot does. The speed is the larger
of the measured one and, in POSCTL, PX4's own velocity setpoint as joyfly estimates it from the sticks it sent
(`SetpointEstimate`): that setpoint runs well ahead of the vehicle while it accelerates, and a rule on the measured
speed alone lets it overshoot. In POSCTL a fully released stick is left alone (PX4's own brake and position lock are
stronger); in ALTCTL, where nothing else stops a drifting vehicle, the brake applies whatever the pilot does.
Vertically, the throttle's climb (descent) is limited to the allowance above (below) the vehicle, down to the
centred throttle, which holds the altitude.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace

from joyfly.sticks.manual import ManualInput, from_throttle
from joyfly.sticks.setpoints import Fence, Vec3
from px4common import manual_defaults as px4

G = 9.80665
STICK_EPS = 1e-6
SNAP = 0.05  # a limited stick component this small (0.3 m/s^2 in POSCTL) is sent as 0: PX4 brakes, holds


@dataclass(frozen=True, slots=True)
class ManualModel:
    """What PX4 does with the sticks (its parameter defaults: px4common/manual_defaults.py) and the braking joyfly
    plans with."""

    vel_manual_m_s: float = px4.MPC_VEL_MANUAL
    acc_hor_m_s2: float = px4.MPC_ACC_HOR
    jerk_max_m_s3: float = px4.MPC_JERK_MAX
    tilt_max_deg: float = px4.MPC_MAN_TILT_MAX
    z_vel_up_m_s: float = px4.MPC_Z_VEL_MAX_UP
    z_vel_down_m_s: float = px4.MPC_Z_VEL_MAX_DN
    deadzone: float = px4.MAN_DEADZONE
    expo: float = px4.STICK_EXPO
    brake_acc_m_s2: float = px4.MPC_ACC_HOR / 2  # planned deceleration
    reaction_s: float = 1.2
    buffer_m: float = 0.5  # where the vehicle stops, inside the fence
    track_gain_1_s: float = 3.0  # how fast the stick pulls the speed to the allowance
    return_gain_1_s: float = 1.0  # past the fence: back in at this many m/s per metre

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
    """The fastest the vehicle may move towards a side `room_m` away (it then stops `buffer_m` short of it); 0 in
    the buffer (no pull back: a stick held still there lets PX4 lock the position, and never looks like a pilot
    moving the sticks); negative past the side: move back in."""
    if room_m < 0.0:
        return room_m * m.return_gain_1_s
    room = room_m - m.buffer_m
    if room <= 0.0:
        return 0.0
    a, t = m.brake_acc_m_s2, m.reaction_s
    return a * (-t + math.sqrt(t * t + 2.0 * room / a))


def _limit_axis(u: float, pos: float, vel: tuple[float, float], centre: float, half_width: float, acc: float,
                drag: float, m: ManualModel) -> float:
    """One world axis of the (shaped) stick, limited against both sides of the fence; `vel` = (measured, PX4's
    setpoint) velocity along the axis."""
    for side in (1.0, -1.0):
        room = (centre + side * half_width - pos) * side
        v_out = max(vel[0] * side, vel[1] * side)
        cap = (m.track_gain_1_s * (allowed_speed(room, m) - v_out) + drag * vel[1] * side) / acc
        if u * side > cap:
            u = cap * side
    return max(-1.0, min(1.0, u))


def heading_to_world(f: float, r: float, yaw: float) -> tuple[float, float]:
    """Body (forward, right) -> world (north, east), as PX4's rotateIntoHeadingFrameXY."""
    c, s = math.cos(yaw), math.sin(yaw)
    return c * f - s * r, s * f + c * r


def unit_limited(f: float, r: float) -> tuple[float, float]:
    norm = math.hypot(f, r)
    return (f / norm, r / norm) if norm > 1.0 else (f, r)


def shaped_world(inp: ManualInput, yaw: float, m: ManualModel = PX4) -> tuple[float, float]:
    """The right stick as PX4's POSCTL acts on it: shaped, limited to the unit circle, rotated into north/east."""
    return heading_to_world(*unit_limited(px4_shape(inp.x / 1000, m), px4_shape(inp.y / 1000, m)), yaw)


def limit_horizontal(x: float, y: float, pos: Vec3, vel: Vec3, yaw: float, fence: Fence, altitude_mode: bool,
                     m: ManualModel = PX4, vel_sp_ne: tuple[float, float] | None = None) -> tuple[float, float]:
    """The right stick (x forward, y right, -1..1) limited by the fence's sides; unchanged when nothing binds.
    `vel_sp_ne`: PX4's POSCTL velocity setpoint as estimated (`SetpointEstimate`), else the measured velocity."""
    if not fence.enabled:
        return x, y
    shape: Callable[[float], float] = (lambda s: s) if altitude_mode else (lambda s: px4_shape(s, m))
    north, east = heading_to_world(*unit_limited(shape(x), shape(y)), yaw)  # PX4 limits the stick to the unit circle
    if not altitude_mode and abs(north) < STICK_EPS and abs(east) < STICK_EPS:
        return x, y  # POSCTL brakes harder and locks the position by itself when the stick is released
    acc, drag = (m.tilt_acc_m_s2, 0.0) if altitude_mode else (m.pos_acc_m_s2, m.pos_drag_1_s)
    hx, hy, _ = fence.home_ned_m
    sp = vel_sp_ne if vel_sp_ne is not None and not altitude_mode else (vel[0], vel[1])
    n2 = _limit_axis(north, pos[0], (vel[0], sp[0]), hx, fence.half_width_m, acc, drag, m)
    e2 = _limit_axis(east, pos[1], (vel[1], sp[1]), hy, fence.half_width_m, acc, drag, m)
    if abs(n2 - north) < STICK_EPS and abs(e2 - east) < STICK_EPS:
        return x, y
    n2, e2 = (0.0 if abs(n2) < SNAP else n2), (0.0 if abs(e2) < SNAP else e2)  # PX4 then brakes and locks
    # back into the heading frame; no residue becomes PX4's deadzone edge
    f, r = (0.0 if abs(v) < SNAP else v for v in heading_to_world(n2, e2, -yaw))
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
                 m: ManualModel = PX4, vel_sp_ne: tuple[float, float] | None = None) -> ManualInput:
    """The MANUAL_CONTROL sticks limited by the fence (horizontal sides, altitude band); yaw passes unchanged.
    `vel_sp_ne`: PX4's POSCTL velocity setpoint as estimated (`SetpointEstimate`), if known."""
    x, y = limit_horizontal(inp.x / 1000, inp.y / 1000, pos, vel, yaw, fence, altitude_mode, m, vel_sp_ne)
    throttle = limit_throttle(inp.throttle, fence.alt_m(pos), -vel[2], fence, m)
    out = replace(inp, x=round(x * 1000) if x != inp.x / 1000 else inp.x,
                  y=round(y * 1000) if y != inp.y / 1000 else inp.y)
    return replace(out, z=from_throttle(throttle)) if throttle != inp.throttle else out


# --- PX4's POSCTL velocity setpoint, estimated from the sticks sent -------------------------------------------------

ESTIMATE_STEP_S = 0.02  # PX4's flight tasks run at 50 Hz
ESTIMATE_STALE_S = 0.5  # a gap this long (no stream) and the estimate starts again from the measured velocity


@dataclass(frozen=True, slots=True)
class SetpointEstimate:
    """PX4's POSCTL horizontal velocity setpoint (north, east) as joyfly estimates it: StickAccelerationXY (spec
    above) run on the stick joyfly sent last (`stick_ne`, shaped and rotated: `shaped_world`), with its jerk limit
    (MPC_JERK_MAX) per axis and without its tilt limit. `time_s` None: nothing to go on yet."""

    vel_ne: tuple[float, float] = (0.0, 0.0)
    boost: float = 1.0
    stick_ne: tuple[float, float] = (0.0, 0.0)
    time_s: float | None = None
    acc_ne: tuple[float, float] = (0.0, 0.0)


def restart_estimate(vel: Vec3, now_s: float) -> SetpointEstimate:
    """PX4 starts the setpoint from the vehicle's velocity (FlightTaskManualAcceleration::activate, and every cycle
    on the ground before the takeoff ramp)."""
    return SetpointEstimate((vel[0], vel[1]), 1.0, (0.0, 0.0), now_s)


def advance_estimate(est: SetpointEstimate, now_s: float, vel: Vec3, m: ManualModel = PX4) -> SetpointEstimate:
    """The estimate at `now_s`, the last stick held since `est.time_s`."""
    if est.time_s is None or not 0.0 <= now_s - est.time_s <= ESTIMATE_STALE_S:
        return restart_estimate(vel, now_s)
    v, a, boost, elapsed = list(est.vel_ne), list(est.acc_ne), est.boost, now_s - est.time_s
    released = est.stick_ne[0] ** 2 + est.stick_ne[1] ** 2 < 1.19e-7
    while elapsed > 1e-9:
        dt = min(ESTIMATE_STEP_S, elapsed)
        elapsed -= dt
        boost += dt / (0.8 + dt) * ((max(2.0, math.sqrt(m.vel_manual_m_s)) if released else 1.0) - boost)
        drag = _drag(v[0], v[1], boost, m)
        if released and v[0] ** 2 + v[1] ** 2 < (drag[0] ** 2 + drag[1] ** 2) * dt * dt:
            v, drag = [0.0, 0.0], (0.0, 0.0)
        for i in (0, 1):
            wanted = m.pos_acc_m_s2 * est.stick_ne[i] - drag[i]
            a[i] += min(max(wanted - a[i], -m.jerk_max_m_s3 * dt), m.jerk_max_m_s3 * dt)
            v[i] += a[i] * dt
    return SetpointEstimate((v[0], v[1]), boost, est.stick_ne, now_s, (a[0], a[1]))


def _drag(vn: float, ve: float, boost: float, m: ManualModel) -> tuple[float, float]:
    """StickAccelerationXY's drag: linear, boosted and square-root shaped below 1 m/s once the stick is released."""
    speed = math.hypot(vn, ve)
    if speed == 0.0:
        return 0.0, 0.0
    c = m.pos_drag_1_s * boost
    brake = min(max(boost - 1.0, 0.0), 1.0)
    boosted = (math.sqrt(speed) if speed < 1.0 else speed) / speed
    scale = c * (brake * boosted + (1.0 - brake))
    return scale * vn, scale * ve


def limit_tracked(inp: ManualInput, pos: Vec3, vel: Vec3, yaw: float, fence: Fence, altitude_mode: bool,
                  est: SetpointEstimate, now_s: float, m: ManualModel = PX4) -> tuple[ManualInput, SetpointEstimate]:
    """`limit_manual` with PX4's POSCTL velocity setpoint estimated along the way: pass the estimate the previous call
    returned (SetpointEstimate() at first, or restart_estimate() when PX4 restarts its setpoint)."""
    est = restart_estimate(vel, now_s) if altitude_mode else advance_estimate(est, now_s, vel, m)
    out = limit_manual(inp, pos, vel, yaw, fence, altitude_mode, m, None if altitude_mode else est.vel_ne)
    return out, replace(est, stick_ne=(0.0, 0.0) if altitude_mode else shaped_world(out, yaw, m))
