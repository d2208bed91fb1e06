"""Quad-X control allocation after PX4's ControlAllocationSequentialDesaturation (src/modules/control_allocator/
ControlAllocation/ControlAllocationSequentialDesaturation.cpp, MC_AIRMODE 0: mixAirmodeDisabled).

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
from dataclasses import dataclass
from typing import Final

from sitl_emu.control.qmath import constrain, isfinite
from sitl_emu.types import Vec3, Vec4

_K: Final = 1.0 / math.sqrt(2.0)


@dataclass(frozen=True, slots=True)
class Effectiveness:
    """The effectiveness columns. Fields of one Final instance, not module tuples: mypyc miscompiles reading a Final
    tuple of floats (mypyc/mypyc#1183), and compiled, a plain module name is a dict look-up at every read."""

    roll: Vec4 = (-_K, _K, _K, -_K)
    pitch: Vec4 = (_K, -_K, _K, -_K)
    yaw: Vec4 = (1.0, 1.0, -1.0, -1.0)
    thrust: Vec4 = (1.0, 1.0, 1.0, 1.0)


COLUMNS: Final = Effectiveness()
YAW_HEADROOM: Final = 1.15  # mixYaw: some yaw authority above full thrust
SATURATION_TOLERANCE: Final = 1e-4
Flags3 = tuple[bool, bool, bool]
_NO_SAT: Final = (False, False, False)


def mix(torque: Vec3, thrust: float) -> tuple[Vec4, Flags3, Flags3]:
    """Motor commands 0..1 for normalised torque (roll, pitch, yaw) and collective thrust 0..1 (NaN counts as 0).

    Also returns per-axis positive/negative saturation flags (the torque achieved fell short of the demand), which
    the rate controller uses to stop integrating into the saturation.
    """
    roll, pitch, yaw = torque
    roll, pitch, yaw = (roll if isfinite(roll) else 0.0, pitch if isfinite(pitch) else 0.0,
                        yaw if isfinite(yaw) else 0.0)
    thrust = thrust if isfinite(thrust) else 0.0
    r, p = _K * roll, _K * pitch  # the roll and pitch columns above, row by row
    u = (thrust - r + p, thrust + r - p, thrust + r + p, thrust - r - p)
    saturated = not _within(u, 1.0)
    if saturated:  # unsaturate with thrust (reducing it only), then roll, then pitch
        u = _desaturate(u, COLUMNS.thrust, 1.0, reduce_only=True)
        u = _desaturate(u, COLUMNS.roll, 1.0)
        u = _desaturate(u, COLUMNS.pitch, 1.0)
    u = (u[0] + yaw, u[1] + yaw, u[2] - yaw, u[3] - yaw)  # mixYaw: the yaw column
    if not _within(u, 1.0):  # unsaturate with yaw (with headroom), then by reducing thrust
        saturated = True
        u = _desaturate(u, COLUMNS.yaw, YAW_HEADROOM)
        u = _desaturate(u, COLUMNS.thrust, 1.0, reduce_only=True)
    if not saturated:  # every desaturation gain would be zero: the demand is met exactly
        return u, _NO_SAT, _NO_SAT
    out = (constrain(u[0], 0.0, 1.0), constrain(u[1], 0.0, 1.0), constrain(u[2], 0.0, 1.0), constrain(u[3], 0.0, 1.0))
    positive, negative = _saturation_flags(allocated_torque(out), (roll, pitch, yaw))
    return out, positive, negative


def _within(u: Vec4, hi: float) -> bool:
    """Every actuator within 0..hi (else computeDesaturationGain would be non-zero)."""
    return 0.0 <= u[0] <= hi and 0.0 <= u[1] <= hi and 0.0 <= u[2] <= hi and 0.0 <= u[3] <= hi


def _desaturation_gain(vec: Vec4, u: Vec4, hi: float) -> float:
    """computeDesaturationGain: the gain along vec that brings the most saturated actuator back into 0..hi."""
    k_min, k_max = _widen_gain_range(vec[0], u[0], hi, 0.0, 0.0)
    k_min, k_max = _widen_gain_range(vec[1], u[1], hi, k_min, k_max)
    k_min, k_max = _widen_gain_range(vec[2], u[2], hi, k_min, k_max)
    k_min, k_max = _widen_gain_range(vec[3], u[3], hi, k_min, k_max)
    return k_min + k_max


def _widen_gain_range(v: float, x: float, hi: float, k_min: float, k_max: float) -> tuple[float, float]:
    """One actuator of computeDesaturationGain: (k_min, k_max) widened to the gain along v that brings x back into
    0..hi. One actuator at a time rather than a loop over the indices (see ARCHITECTURE.md, On the tick path)."""
    if abs(v) < 1.2e-7:  # FLT_EPSILON: this axis cannot move this actuator
        return k_min, k_max
    if x < 0.0:
        k = -x / v
        k_min, k_max = (k if k < k_min else k_min), (k if k > k_max else k_max)
    if x > hi:
        k = (hi - x) / v
        k_min, k_max = (k if k < k_min else k_min), (k if k > k_max else k_max)
    return k_min, k_max


def _desaturate(u: Vec4, vec: Vec4, hi: float, reduce_only: bool = False) -> Vec4:
    """desaturateActuators: move u along vec to unsaturate, then by half of what is still saturated."""
    gain = _desaturation_gain(vec, u, hi)
    if reduce_only and gain > 0.0:
        return u
    u = _plus_scaled(u, vec, gain)
    return _plus_scaled(u, vec, 0.5 * _desaturation_gain(vec, u, hi))


def _plus_scaled(u: Vec4, vec: Vec4, gain: float) -> Vec4:
    return u[0] + gain * vec[0], u[1] + gain * vec[1], u[2] + gain * vec[2], u[3] + gain * vec[3]


def _saturation_flags(achieved: Vec3, demand: Vec3) -> tuple[Flags3, Flags3]:
    """Per axis: the torque achieved fell short of a positive (negative) demand."""
    tol = SATURATION_TOLERANCE
    positive = (achieved[0] < demand[0] - tol, achieved[1] < demand[1] - tol, achieved[2] < demand[2] - tol)
    negative = (achieved[0] > demand[0] + tol, achieved[1] > demand[1] + tol, achieved[2] > demand[2] + tol)
    return positive, negative


def allocated_torque(u: Vec4) -> Vec3:
    """Normalised torque that motor commands u produce (inverse of the mix above)."""
    c = COLUMNS
    return _dot4(c.roll, u) / (4 * _K * _K), _dot4(c.pitch, u) / (4 * _K * _K), _dot4(c.yaw, u) / 4.0


def _dot4(a: Vec4, b: Vec4) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
