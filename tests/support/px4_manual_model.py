"""A small model of what PX4 does with MANUAL_CONTROL sticks in POSCTL and ALTCTL, to test joyfly's fence limiting
(joyfly/sticks/manual_fence.py) without a vehicle. Written from the notes on PX4 main (2026) in
../notes/px4_manual_spec.md, 3.2-4.1 (StickAccelerationXY, StickTiltXY, ManualVelocitySmoothingZ), simplified:

- POSCTL: the shaped, heading-rotated stick commands A = 6 m/s^2 against a drag of 0.6 1/s x the velocity setpoint;
  a released stick boosts the drag (to 3.16 x, filtered with tau 0.8 s, square-root below 1 m/s) and zeroes a small
  setpoint; the acceleration is jerk-limited (8 m/s^3) and tilt-limited (45 deg);
- ALTCTL: the raw stick tilts the vehicle: tan(35 deg) x g at full stick, only the airframe's drag slows it;
- vertical: the shaped throttle sets a climb (3 m/s) or descent (1.5 m/s) target, reached at 3 m/s^2 at most;
- the vehicle follows its velocity setpoint with a first-order lag (`lag_s`), tuned so that a POSCTL vehicle
  released at 6 m/s needs a little further to stop (11.4 m) than real PX4 did in the reference trace p_fwd (10.5 m).
  (Held at full stick it gets faster than real PX4, 8.5 m/s after 4 s against 6: pessimistic too.)
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field

from joyfly.sticks.manual_fence import G, heading_to_world, px4_shape, unit_limited

EPS = 1.19e-7  # FLT_EPSILON
Vec2 = list[float]


@dataclass
class Plant:
    """One vehicle: horizontal position/velocity (NED x, y), altitude above home, climb rate."""

    altitude_mode: bool = False
    yaw: float = 0.0
    lag_s: float = 0.4
    drag_1_s: float = 0.3  # ALTCTL: the airframe's drag
    pos: Vec2 = field(default_factory=lambda: [0.0, 0.0])
    vel: Vec2 = field(default_factory=lambda: [0.0, 0.0])
    alt: float = 5.0
    climb: float = 0.0
    v_sp: Vec2 = field(default_factory=lambda: [0.0, 0.0])
    acc_sp: Vec2 = field(default_factory=lambda: [0.0, 0.0])
    climb_sp: float = 0.0
    boost: float = 1.0

    def step(self, x: float, y: float, throttle: float, dt: float) -> None:
        """x, y, throttle as PX4 reads MANUAL_CONTROL (-1..1)."""
        if self.altitude_mode:
            self._altctl_xy(x, y, dt)
        else:
            self._posctl_xy(x, y, dt)
        self._vertical(throttle, dt)

    def _posctl_xy(self, x: float, y: float, dt: float) -> None:
        e = heading_to_world(*unit_limited(px4_shape(x), px4_shape(y)), self.yaw)
        released = e[0] ** 2 + e[1] ** 2 < EPS
        self.boost += dt / (0.8 + dt) * ((max(2.0, math.sqrt(10.0)) if released else 1.0) - self.boost)
        speed = math.hypot(*self.v_sp)
        sqrt_lin = math.sqrt(speed) if speed < 1.0 else speed
        unit = [v / speed for v in self.v_sp] if speed > 0 else [0.0, 0.0]
        brake = min(max(self.boost - 1.0, 0.0), 1.0)
        drag = [0.6 * self.boost * (brake * u * sqrt_lin + (1 - brake) * v) for u, v in zip(unit, self.v_sp,
                                                                                           strict=True)]
        if released and speed ** 2 < (drag[0] ** 2 + drag[1] ** 2) * dt * dt:
            drag, self.v_sp = [0.0, 0.0], [0.0, 0.0]
        acc = [6.0 * ei - d for ei, d in zip(e, drag, strict=True)]
        acc = [p + min(max(a - p, -8.0 * dt), 8.0 * dt) for a, p in zip(acc, self.acc_sp, strict=True)]
        norm = math.hypot(*acc)
        self.acc_sp = [a * G / norm for a in acc] if norm > G else acc
        self.v_sp = [v + a * dt for v, a in zip(self.v_sp, self.acc_sp, strict=True)]
        self.vel = [v + (s - v) * dt / self.lag_s for v, s in zip(self.vel, self.v_sp, strict=True)]
        self.pos = [p + v * dt for p, v in zip(self.pos, self.vel, strict=True)]

    def _altctl_xy(self, x: float, y: float, dt: float) -> None:
        e = heading_to_world(*unit_limited(x, y), self.yaw)
        tilt = math.tan(math.radians(35.0)) * G
        target = [tilt * ei for ei in e]
        self.acc_sp = [a + (t - a) * dt / 0.2 for a, t in zip(self.acc_sp, target, strict=True)]
        self.vel = [v + (a - self.drag_1_s * v) * dt for v, a in zip(self.vel, self.acc_sp, strict=True)]
        self.pos = [p + v * dt for p, v in zip(self.pos, self.vel, strict=True)]

    def _vertical(self, throttle: float, dt: float) -> None:
        e = px4_shape(throttle)
        target = e * (3.0 if throttle > 0 else 1.5)
        self.climb_sp += min(max(target - self.climb_sp, -3.0 * dt), 3.0 * dt)
        self.climb += (self.climb_sp - self.climb) * dt / 0.3
        self.alt += self.climb * dt


class Delayed:
    """What joyfly knows of the plant: its state `delay_steps` steps ago (the telemetry's age)."""

    def __init__(self, delay_steps: int) -> None:
        self._queue: deque[tuple[tuple[float, float, float], tuple[float, float, float]]] = deque(
            maxlen=delay_steps + 1)

    def push(self, plant: Plant) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
        """Record the plant's state now; return (pos NED, vel NED) as joyfly sees them."""
        self._queue.append(((plant.pos[0], plant.pos[1], -plant.alt), (plant.vel[0], plant.vel[1], -plant.climb)))
        return self._queue[0]
