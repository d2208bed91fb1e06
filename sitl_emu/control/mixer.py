"""Quad-X control allocation after PX4's ControlAllocationSequentialDesaturation (MC_AIRMODE 0).

The effectiveness matrix of the 10040_sihsim_quadx airframe, pseudo-inverted and normalised as PX4 does
(ControlAllocationPseudoInverse::updateControlAllocationMatrixScale), gives for rotors r0 front-right, r1 rear-left,
r2 front-left, r3 rear-right:
    u_i = T + R_i * roll + P_i * pitch + Y_i * yaw   with R = 0.707 (-1, +1, +1, -1), P = 0.707 (+1, -1, +1, -1),
    Y = (+1, +1, -1, -1)
which matches the SIH moments (physics.py): a positive normalised torque produces a positive body moment.
Saturation (mixAirmodeDisabled): mix roll/pitch/thrust, only reduce thrust to unsaturate, then reduce roll and pitch;
then add yaw, reduce yaw (with 15 % headroom above the maximum), and reduce thrust again. Outputs clipped to 0..1.
"""

from __future__ import annotations

import math
from typing import Final

from sitl_emu.types import Vec3, Vec4

_K: Final = 1.0 / math.sqrt(2.0)
ROLL: Final = (-_K, _K, _K, -_K)
PITCH: Final = (_K, -_K, _K, -_K)
YAW: Final = (1.0, 1.0, -1.0, -1.0)
THRUST: Final = (1.0, 1.0, 1.0, 1.0)
_NO_SAT: Final = (False, False, False)
# isfinite(x) is written `x - x == 0.0` (exact for floats: finite gives 0.0, inf and NaN give NaN): no call when
# compiled by `make speedups` (mypyc has no isfinite primitive).


def _desat_gain(vec: Vec4, u: list[float], lo: float, hi: float) -> float:
    """ControlAllocationSequentialDesaturation::computeDesaturationGain."""
    k_min = k_max = 0.0
    for i in range(4):
        d = vec[i]
        if abs(d) < 1.2e-7:
            continue
        if u[i] < lo:
            k = (lo - u[i]) / d
            k_min, k_max = min(k_min, k), max(k_max, k)
        if u[i] > hi:
            k = (hi - u[i]) / d
            k_min, k_max = min(k_min, k), max(k_max, k)
    return k_min + k_max


def _desaturate(u: list[float], vec: Vec4, lo: float, hi: float, reduce_only: bool = False) -> None:
    gain = _desat_gain(vec, u, lo, hi)
    if reduce_only and gain > 0.0:
        return
    for i in range(4):
        u[i] += gain * vec[i]
    gain = 0.5 * _desat_gain(vec, u, lo, hi)
    for i in range(4):
        u[i] += gain * vec[i]


def mix(torque: Vec3, thrust: float) -> tuple[Vec4, tuple[bool, bool, bool], tuple[bool, bool, bool]]:
    """Motor commands 0..1 for normalised torque (roll, pitch, yaw) and collective thrust 0..1.

    Also returns per-axis positive/negative saturation flags (the torque achieved fell short of the demand), which
    the rate controller uses to stop integrating into the saturation.
    """
    roll, pitch, yaw = torque  # every tick: no generators, no min()/max() on the fast path
    roll = roll if roll - roll == 0.0 else 0.0
    pitch = pitch if pitch - pitch == 0.0 else 0.0
    yaw = yaw if yaw - yaw == 0.0 else 0.0
    thrust = thrust if thrust - thrust == 0.0 else 0.0
    r, p = _K * roll, _K * pitch
    f0, f1, f2, f3 = thrust - r + p + yaw, thrust + r - p + yaw, thrust + r + p - yaw, thrust - r - p - yaw
    # min(fast) >= 0 and max(fast) <= 1, with min()/max()'s own rule (a later item replaces only if < / >)
    lo = f1 if f1 < f0 else f0
    lo = f2 if f2 < lo else lo
    lo = f3 if f3 < lo else lo
    if lo >= 0.0:
        hi = f1 if f1 > f0 else f0
        hi = f2 if f2 > hi else hi
        hi = f3 if f3 > hi else hi
        if hi <= 1.0:  # nothing saturates: the plain mix
            return (f0, f1, f2, f3), _NO_SAT, _NO_SAT
    u = [thrust + ROLL[i] * roll + PITCH[i] * pitch for i in range(4)]
    _desaturate(u, THRUST, 0.0, 1.0, reduce_only=True)
    _desaturate(u, ROLL, 0.0, 1.0)
    _desaturate(u, PITCH, 0.0, 1.0)
    for i in range(4):
        u[i] += YAW[i] * yaw
    _desaturate(u, YAW, 0.0, 1.15)
    _desaturate(u, THRUST, 0.0, 1.0, reduce_only=True)
    out = tuple(0.0 if v < 0.0 else (1.0 if v > 1.0 else v) for v in u)
    achieved = allocated_torque(out)  # type: ignore[arg-type]
    demand = (roll, pitch, yaw)
    pos = tuple(achieved[i] < demand[i] - 1e-4 for i in range(3))
    neg = tuple(achieved[i] > demand[i] + 1e-4 for i in range(3))
    return out, pos, neg  # type: ignore[return-value]


def allocated_torque(u: Vec4) -> Vec3:
    """Normalised torque that motor commands u produce (inverse of the mix above)."""
    return (sum(ROLL[i] * u[i] for i in range(4)) / (4 * _K * _K),
            sum(PITCH[i] * u[i] for i in range(4)) / (4 * _K * _K),
            sum(YAW[i] * u[i] for i in range(4)) / 4.0)
