"""Estimator noise: what the controllers and LOCAL_POSITION_NED see is the truth plus white noise plus a bias that
wanders (a random walk), on position, velocity and attitude. This is the vehicle's one noise model
(`Vehicle(estimate_noise=...)`, `Sim(estimate_noise=...)`).

Per axis and per tick: bias += walk * sqrt(dt) * N(0, 1); estimate = truth + bias + white * N(0, 1). Attitude noise
is a small rotation (rotation vector in the body frame, rad) applied to the true attitude. Every level defaults to 0,
and then the estimate is the truth, exactly (no draw is made); a quantity whose two levels are 0 is the truth's.

On the ground the noise is the same as in flight. PX4's EKF2 keeps fusing the GNSS position and velocity and the
barometer while landed (its zero-velocity update, aid_sources/ZeroVelocityUpdate.cpp, acts only when nothing aids
the vertical velocity; its fake-position fusion only without any position aiding), so its estimate is never pinned
to the pad: PX4 SIH's LOCAL_POSITION_NED, recorded, wanders by centimetres and reads a few cm/s while the vehicle
stands disarmed. The truth stays on the ground; the land detector and the commander read the noisy estimate, as
PX4's do.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import TYPE_CHECKING

from sitl_emu.control.qmath import q_mul
from sitl_emu.physics import RIGID_BODY_FIELDS, RigidBodyState
from sitl_emu.types import Vec3, Vec4

if TYPE_CHECKING:  # numpy is imported where noise is drawn: a vehicle without noise or wind never loads it
    import numpy as np


@dataclass(frozen=True, slots=True)
class EstimateNoiseSettings:
    """1-sigma white noise and bias random-walk intensities (per sqrt(s)) of the estimate."""

    pos_white_m: float = 0.0
    pos_walk_m: float = 0.0
    vel_white_m_s: float = 0.0
    vel_walk_m_s: float = 0.0
    att_white_rad: float = 0.0
    att_walk_rad: float = 0.0

    @property
    def active(self) -> bool:
        return any(v > 0.0 for v in (self.pos_white_m, self.pos_walk_m, self.vel_white_m_s, self.vel_walk_m_s,
                                     self.att_white_rad, self.att_walk_rad))

    @classmethod
    def from_mapping(cls, levels: Mapping[str, object]) -> EstimateNoiseSettings:
        """From plain data (a campaign's `estimate_noise = { pos_white_m = 0.3 }`); ValueError in one sentence."""
        names = [f.name for f in fields(cls)]
        unknown = sorted(set(levels) - set(names))
        if unknown:
            raise ValueError(f"estimate_noise has no level {unknown[0]!r}; the levels are {', '.join(names)}.")
        values: dict[str, float] = {}
        for name, value in levels.items():
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0.0 <= value < math.inf:
                raise ValueError(f"estimate_noise {name} must be a number from 0 up, not {value!r}.")
            values[name] = float(value)
        return cls(**values)


class _Channel:
    """One 3-axis quantity: white noise plus a random-walk bias."""

    def __init__(self, white: float, walk: float) -> None:
        import numpy as np

        self.white, self.walk = white, walk
        self.bias = np.zeros(3)

    def draw(self, rng: np.random.Generator, dt_s: float) -> np.ndarray:
        if self.walk > 0.0:
            self.bias = self.bias + self.walk * math.sqrt(dt_s) * rng.standard_normal(3)
        if self.white > 0.0:
            return self.bias + self.white * rng.standard_normal(3)
        return self.bias


def _channel(white: float, walk: float) -> _Channel | None:
    return _Channel(white, walk) if white > 0.0 or walk > 0.0 else None


class EstimateNoise:
    """Turns the truth into the estimate, tick by tick (seeded), on the ground as in flight (module docstring)."""

    def __init__(self, settings: EstimateNoiseSettings, rng: np.random.Generator) -> None:
        self.settings = settings
        self._rng = rng
        s = settings
        self._pos = _channel(s.pos_white_m, s.pos_walk_m)
        self._vel = _channel(s.vel_white_m_s, s.vel_walk_m_s)
        self._att = _channel(s.att_white_rad, s.att_walk_rad)

    def apply(self, truth: RigidBodyState, dt_s: float) -> RigidBodyState:
        est = RigidBodyState(**{f: getattr(truth, f) for f in RIGID_BODY_FIELDS})
        rng = self._rng
        if self._pos is not None:
            est.pos_ned_m = _add(truth.pos_ned_m, self._pos.draw(rng, dt_s))
        if self._vel is not None:
            est.vel_ned_m_s = _add(truth.vel_ned_m_s, self._vel.draw(rng, dt_s))
        if self._att is not None:
            est.q_wxyz = _rotated(truth.q_wxyz, self._att.draw(rng, dt_s))
        return est


def _add(v: Vec3, n: np.ndarray) -> Vec3:
    return (v[0] + float(n[0]), v[1] + float(n[1]), v[2] + float(n[2]))


def _rotated(q: Vec4, rot: np.ndarray) -> Vec4:
    import numpy as np

    angle = float(np.linalg.norm(rot))
    if angle < 1e-12:
        return q
    k = math.sin(0.5 * angle) / angle
    return q_mul(q, (math.cos(0.5 * angle), float(rot[0]) * k, float(rot[1]) * k, float(rot[2]) * k))
