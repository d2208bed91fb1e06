"""PX4's follow-target estimator: an alpha-beta-gamma filter on the target's FOLLOW_TARGET fixes.

Written from src/modules/flight_mode_manager/tasks/AutoFollowTarget/follow_target_estimator/TargetEstimator.{hpp,cpp}:
- it runs only while Follow Target flies (the flight task starts it) and predicts position, velocity and
  acceleration every cycle;
- a fix is fused unless it has the same receipt time as the last or is older than the last position fusion; the
  first fix sets the state (velocity 0 when the fix has none); position at most every 500 ms (or when it changed),
  velocity at most every 100 ms, with gains from FLW_TGT_RS (constrained to 0.1..1): beta = RS^(1/3);
- no fix for 3 s: the target is stale, velocity and acceleration are zeroed (the estimate stays where it was);
- a state that is not finite (a NaN altitude in the first fix, for instance) resets the filter: no valid estimate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final

from sitl_emu.control.qmath import constrain, isfinite
from sitl_emu.types import NAN3, Vec3

STALE_US: Final = 3_000_000  # GPS_MESSAGE_STALE_TIMEOUT_MS
POS_FUSION_MIN_US: Final = 500_000  # MINIMUM_TIME_BETWEEN_POS_FUSIONS_MS
VEL_FUSION_MIN_US: Final = 100_000  # MINIMUM_TIME_BETWEEN_VEL_FUSIONS_MS
ACC_SATURATION: Final = 20.0
_EPS2: Final = 2.0 * 1.1920929e-07


@dataclass(frozen=True, slots=True)
class TargetFix:
    """One FOLLOW_TARGET in the local frame (NaN where the message had none), stamped with its receipt time."""

    time_us: int
    pos_ned_m: Vec3
    vel_ned_m_s: Vec3


@dataclass(frozen=True, slots=True)
class TargetEstimate:
    """follow_target_estimator: valid (finite state), stale (no fix for 3 s), position and velocity."""

    valid: bool
    stale: bool
    pos_ned_m: Vec3
    vel_ned_m_s: Vec3


def _finite(v: Vec3) -> bool:
    return isfinite(v[0]) and isfinite(v[1]) and isfinite(v[2])


def _add(a: Vec3, b: Vec3, k: float = 1.0) -> Vec3:
    return a[0] + k * b[0], a[1] + k * b[1], a[2] + k * b[2]


def _sub(a: Vec3, b: Vec3) -> Vec3:
    return a[0] - b[0], a[1] - b[1], a[2] - b[2]


class TargetEstimator:
    def __init__(self, responsiveness: float) -> None:
        b = constrain(responsiveness, 0.1, 1.0) ** (1.0 / 3.0)
        bv = 0.9 * b
        self.g_p, self.h_p, self.k_p = 1.0 - b ** 3, 1.5 * (1.0 - b) ** 2 * (1.0 + b), 0.5 * (1.0 - b) ** 3
        self.g_v, self.h_v = 1.0 - bv * bv, (1.0 - bv) ** 2
        self._last_iter_us = 0
        self._fix_seen: TargetFix | None = None
        self.reset()

    def reset(self) -> None:
        self.pos: Vec3 = NAN3
        self.vel: Vec3 = NAN3
        self.acc: Vec3 = NAN3
        self._last_fix_us = self._last_pos_us = self._last_vel_us = 0
        self._pos_old: Vec3 = NAN3
        self._vel_old: Vec3 = NAN3

    def update(self, now_us: int, fix: TargetFix | None) -> TargetEstimate | None:
        """One cycle with the latest fix (a fix already seen is skipped); None on the very first call (no output)."""
        if self._last_iter_us == 0:
            self._last_iter_us = now_us
            return None
        dt = constrain((now_us - self._last_iter_us) * 1e-6, 1e-3, 2.0)
        self._last_iter_us = now_us
        self._predict(dt)
        if fix is not None and fix is not self._fix_seen:
            self._fix_seen = fix
            if fix.time_us != self._last_fix_us and self._last_pos_us < fix.time_us:
                self._measure(fix, now_us)
        stale = now_us - self._last_fix_us >= STALE_US
        if stale:
            self.vel, self.acc = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
        valid = _finite(self.pos) and _finite(self.vel) and _finite(self.acc)
        if not valid:
            self.reset()
        return TargetEstimate(valid, stale, self.pos, self.vel)

    def _predict(self, dt: float) -> None:
        vel, acc = self.vel, self.acc
        if _finite(vel):
            self.pos = _add(_add(self.pos, vel, dt), acc, 0.5 * dt * dt)
        if _finite(acc):
            self.vel = _add(vel, acc, dt)

    def _measure(self, fix: TargetFix, now_us: int) -> None:
        pos_m, vel_m = fix.pos_ned_m, fix.vel_ned_m_s
        if self._last_fix_us == 0:  # the first fix sets the state
            self.pos, self.vel = pos_m, vel_m if _finite(vel_m) else (0.0, 0.0, 0.0)
            self.acc, self._pos_old, self._vel_old = (0.0, 0.0, 0.0), pos_m, vel_m
        self._last_fix_us = fix.time_us
        if _fusable(pos_m, self._pos_old, now_us - self._last_pos_us, POS_FUSION_MIN_US):
            dt = constrain((fix.time_us - self._last_pos_us) * 1e-6, 1e-3, 20.0)
            self._last_pos_us = fix.time_us
            innov = _sub(pos_m, self.pos)
            self.pos = _add(self.pos, innov, self.g_p)
            self.vel = _add(self.vel, innov, self.h_p / dt)
            self.acc = _add(self.acc, innov, 2.0 * self.k_p / (dt * dt))
            self._pos_old = pos_m
        if _fusable(vel_m, self._vel_old, now_us - self._last_vel_us, VEL_FUSION_MIN_US):
            dt = constrain((fix.time_us - self._last_vel_us) * 1e-6, 1e-3, 20.0)
            self._last_vel_us = fix.time_us
            innov = _sub(vel_m, self.vel)
            self.vel = _add(self.vel, innov, self.g_v)
            self.acc = _add(self.acc, innov, self.h_v / dt)
            self._vel_old = vel_m
        norm = math.sqrt(sum(a * a for a in self.acc))
        if norm > ACC_SATURATION:
            self.acc = tuple(a * ACC_SATURATION / norm for a in self.acc)  # type: ignore[assignment]


def _fusable(current: Vec3, previous: Vec3, since_us: int, min_us: int) -> bool:
    """measurement_can_be_fused: finite, not too soon, and changed (or not fused for twice the minimum)."""
    d = _sub(current, previous)
    changed = not _finite(previous) or math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) > _EPS2
    return _finite(current) and since_us > min_us and (changed or since_us > 2 * min_us)
