"""A closed loop of physics + control cascade in simulated time, for tests, fidelity checks and benchmarks.

The land detector is replaced by the physics' ground contact (`landed = state.on_ground`), which is enough to run
takeoff handling; the vehicle integration uses the real land detector.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from sitl_emu.control.cascade import MulticopterControl
from sitl_emu.control.qmath import tilt_from_q
from sitl_emu.control.takeoff import TakeoffState
from sitl_emu.params import ParamRegistry, default_registry
from sitl_emu.params.settings import cascade_settings, sih_config
from sitl_emu.physics import RigidBodyState, step
from sitl_emu.types import AttitudeSetpoint, TrajectorySetpoint, Vec4

SetpointFn = Callable[[float], TrajectorySetpoint | None]


@dataclass(slots=True)
class Trace:
    t_s: list[float] = field(default_factory=list)
    states: list[RigidBodyState] = field(default_factory=list)
    motors: list[Vec4] = field(default_factory=list)
    takeoff_state: list[TakeoffState] = field(default_factory=list)
    failsafe: list[bool] = field(default_factory=list)

    def column(self, name: str, i: int) -> list[float]:
        return [getattr(s, name)[i] for s in self.states]

    def tilt_rad(self) -> list[float]:
        return [tilt_from_q(s.q_wxyz) for s in self.states]


class ClosedLoop:
    def __init__(self, registry: ParamRegistry | None = None, state: RigidBodyState | None = None,
                 flying: bool = False, dt_s: float = 0.004) -> None:
        self.registry = registry or default_registry()
        self.cfg = sih_config(self.registry)
        self.control = MulticopterControl(cascade_settings(self.registry))
        self._params_watch = self.registry.changes.watch()  # params/changes.py
        self.control.reset(flying=flying)
        self.state = state or RigidBodyState()
        self.dt_s = dt_s
        self.now_us = 0

    def run(self, duration_s: float, setpoint: SetpointFn, armed: bool = True,
            attitude: Callable[[float], AttitudeSetpoint | None] | None = None, trace: Trace | None = None,
            t0_s: float = 0.0) -> Trace:
        trace = trace or Trace()
        dt_us = round(self.dt_s * 1e6)
        for k in range(round(duration_s / self.dt_s)):
            t = t0_s + k * self.dt_s
            att = attitude(t) if attitude else None
            if self._params_watch.changed():  # a parameter changed: new controller settings
                self.control.settings = cascade_settings(self.registry)
            motors = self.control.update(self.state, setpoint(t), att, armed, self.state.on_ground,
                                         self.now_us, self.dt_s)
            self.state = step(self.state, motors, self.dt_s, self.cfg)
            self.now_us += dt_us
            trace.t_s.append(t + self.dt_s)
            trace.states.append(self.state)
            trace.motors.append(motors)
            trace.takeoff_state.append(self.control.takeoff_state)
            trace.failsafe.append(self.control.in_failsafe)
        return trace


def hover_loop(altitude_m: float = 2.5, registry: ParamRegistry | None = None, settle_s: float = 5.0) -> ClosedLoop:
    """A loop whose vehicle took off from the ground to `altitude_m` and settled there (position setpoint)."""
    loop = ClosedLoop(registry)
    sp = TrajectorySetpoint(position_ned_m=(0.0, 0.0, -altitude_m))
    loop.run(1.0 + loop.control.settings.tko_ramp_t_s + settle_s, lambda t: sp)
    return loop
