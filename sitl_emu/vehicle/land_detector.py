"""PX4's multicopter land detector (src/modules/land_detector/{LandDetector,MulticopterLandDetector}.cpp).

Three hysteresis stages, each LNDMC_TRIG_TIME / 3 (1 s in total by default), from false to true only; any stage
drops to false at once (so takeoff is detected immediately):
- ground contact: low thrust, no vertical movement (|vz| < LNDMC_Z_VEL_MAX, x2.5 once maybe landed), no horizontal
  movement (< LNDMC_XY_VEL_MAX) and, under climb-rate control, a descending velocity setpoint until maybe landed;
- maybe landed: ground contact held, minimal thrust, no freefall, roll/pitch rates < LNDMC_ROT_MAX (x2.5 once
  maybe landed);
- landed: maybe landed held.
Freefall: specific force below 2 m/s^2 for 300 ms. Disarmed: everything but freefall is true.
The emulator has no distance sensor input here, so the close-to-ground check is skipped as PX4 does without one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final

from sitl_emu.control.qmath import hypot, isfinite
from sitl_emu.params import ParamRegistry
from sitl_emu.types import Vec3

FREEFALL_ACC_M_S2: Final = 2.0  # MulticopterLandDetector::_get_freefall_state
FREEFALL_TRIGGER_US: Final = 300_000  # LandDetector.h FREEFALL_TRIGGER_TIME_US
DESCENT_FACTOR: Final = 1.1  # in descent: velocity setpoint z >= 1.1 * LNDMC_Z_VEL_MAX
WIDEN_FACTOR: Final = 2.5  # thresholds widen once maybe landed


@dataclass(slots=True)
class LandDetectorInput:
    """One detector cycle's input; read-only by convention, as LandDetectorState (see ARCHITECTURE.md, On the tick
    path)."""

    time_us: int
    armed: bool
    vel_ned_m_s: Vec3
    rates_frd_rad_s: Vec3
    specific_force_norm_m_s2: float
    thrust_setpoint: float  # collective 0..1 the controller commands
    hover_thrust: float  # 0..1
    setpoint_vz_m_s: float  # vertical velocity setpoint (NaN if none)
    in_descent_mode: bool  # climb rate controlled (PX4 flag_control_climb_rate_enabled), e.g. land/idle/position

    def __init__(self, time_us: int, armed: bool, vel_ned_m_s: Vec3, rates_frd_rad_s: Vec3,
                 specific_force_norm_m_s2: float, thrust_setpoint: float, hover_thrust: float, setpoint_vz_m_s: float,
                 in_descent_mode: bool) -> None:
        self.time_us = time_us
        self.armed = armed
        self.vel_ned_m_s = vel_ned_m_s
        self.rates_frd_rad_s = rates_frd_rad_s
        self.specific_force_norm_m_s2 = specific_force_norm_m_s2
        self.thrust_setpoint = thrust_setpoint
        self.hover_thrust = hover_thrust
        self.setpoint_vz_m_s = setpoint_vz_m_s
        self.in_descent_mode = in_descent_mode


@dataclass(slots=True)
class LandDetectorState:
    landed: bool
    maybe_landed: bool
    ground_contact: bool
    freefall: bool

    def __init__(self, landed: bool, maybe_landed: bool, ground_contact: bool, freefall: bool) -> None:
        self.landed = landed
        self.maybe_landed = maybe_landed
        self.ground_contact = ground_contact
        self.freefall = freefall


class Hysteresis:
    """systemlib::Hysteresis: the state follows the request after it has been held for the transition's time."""

    __slots__ = ("_changed_us", "_requested", "state", "time_from_false_us", "time_from_true_us")

    def __init__(self, state: bool, time_from_false_us: int = 0, time_from_true_us: int = 0) -> None:
        self.state = self._requested = state
        self._changed_us = 0
        self.time_from_false_us = time_from_false_us
        self.time_from_true_us = time_from_true_us

    def set_state_and_update(self, new_state: bool, now_us: int) -> None:
        if new_state != self.state:
            if new_state != self._requested:
                self._requested = new_state
                self._changed_us = now_us
        else:
            self._requested = self.state
        if self._requested != self.state:
            wait = self.time_from_false_us if self._requested else self.time_from_true_us
            if now_us - self._changed_us >= wait:
                self.state = self._requested

    def reset(self, state: bool) -> None:
        self.state = self._requested = state


@dataclass(frozen=True, slots=True)
class _Settings:
    z_vel_max: float
    xy_vel_max: float
    rot_max_rad_s: float
    stage_us: int
    thr_min: float
    man_thr_min: float
    use_hte: bool

    @classmethod
    def from_params(cls, p: ParamRegistry) -> _Settings:
        def get(name: str, default: float) -> float:
            return float(p.get(name)) if name in p else default

        return cls(get("LNDMC_Z_VEL_MAX", 0.25), get("LNDMC_XY_VEL_MAX", 1.5),
                   math.radians(get("LNDMC_ROT_MAX", 20.0)), int(get("LNDMC_TRIG_TIME", 1.0) * 1e6 / 3),
                   get("MPC_THR_MIN", 0.12), get("MPC_MANTHR_MIN", 0.08), get("MPC_USE_HTE", 1) == 1)


class LandDetector:
    """Feed it every cycle; it returns the published land-detected state."""

    def __init__(self, params: ParamRegistry) -> None:
        self._params = params
        self._params_watch = params.changes.watch(current=False)  # params/changes.py
        self._s = _Settings.from_params(params)
        self._freefall = Hysteresis(False, FREEFALL_TRIGGER_US)
        self._ground_contact = Hysteresis(True)
        self._maybe_landed = Hysteresis(True)
        self._landed = Hysteresis(True)
        self._published = LandDetectorState(True, True, True, False)  # the last state made (see state)
        self._refresh()

    def reset(self, landed: bool = True) -> None:
        for h in (self._ground_contact, self._maybe_landed, self._landed):
            h.reset(landed)
        self._freefall.reset(False)

    def update(self, inp: LandDetectorInput) -> LandDetectorState:
        """One detector cycle (PX4 runs it at 50 Hz): the published land-detected state."""
        self._refresh()
        now_us = inp.time_us
        self._freefall.set_state_and_update(inp.specific_force_norm_m_s2 < FREEFALL_ACC_M_S2, now_us)
        if inp.armed:
            self._ground_contact.set_state_and_update(self._ground_contact_now(inp), now_us)
            self._maybe_landed.set_state_and_update(self._maybe_landed_now(inp), now_us)
            self._landed.set_state_and_update(self._maybe_landed.state, now_us)
        else:  # disarmed: every stage is requested true (freefall aside)
            self._ground_contact.set_state_and_update(True, now_us)
            self._maybe_landed.set_state_and_update(True, now_us)
            self._landed.set_state_and_update(True, now_us)
        return self.state

    @property
    def state(self) -> LandDetectorState:
        """The published state: the last one again while no flag changed (it is read-only, and made 50 times a
        second)."""
        landed, maybe, contact, freefall = (self._landed.state, self._maybe_landed.state, self._ground_contact.state,
                                            self._freefall.state)
        last = self._published
        if (last.landed, last.maybe_landed, last.ground_contact, last.freefall) != (landed, maybe, contact, freefall):
            last = self._published = LandDetectorState(landed, maybe, contact, freefall)
        return last

    def _refresh(self) -> None:
        if not self._params_watch.changed():
            return
        self._s = _Settings.from_params(self._params)
        for h in (self._ground_contact, self._maybe_landed, self._landed):
            h.time_from_false_us = self._s.stage_us

    def _ground_contact_now(self, inp: LandDetectorInput) -> bool:
        """Armed only (disarmed: true)."""
        s = self._s
        vel = inp.vel_ned_m_s
        vz_limit = s.z_vel_max * (WIDEN_FACTOR if self._maybe_landed.state else 1.0)
        vertical_movement = abs(vel[2]) > vz_limit
        horizontal_movement = hypot(vel[0], vel[1]) > s.xy_vel_max
        share = 0.6 if s.use_hte else 0.3  # 60 % of the min..hover range with a hover-thrust estimate, else 30 %
        contact = inp.thrust_setpoint <= s.thr_min + (inp.hover_thrust - s.thr_min) * share
        if inp.in_descent_mode and not self._maybe_landed.state and not self._landed.state:
            vz_sp = inp.setpoint_vz_m_s
            contact = contact and isfinite(vz_sp) and vz_sp >= DESCENT_FACTOR * s.z_vel_max
        return contact and not horizontal_movement and not vertical_movement

    def _maybe_landed_now(self, inp: LandDetectorInput) -> bool:
        """Armed only (disarmed: true)."""
        s = self._s
        min_thrust = s.thr_min + (inp.hover_thrust - s.thr_min) * 0.1
        if not inp.in_descent_mode:
            min_thrust = s.man_thr_min + 0.01
        if inp.thrust_setpoint > min_thrust or self._freefall.state:
            return False
        rot_limit = s.rot_max_rad_s * (WIDEN_FACTOR if self._maybe_landed.state else 1.0)
        if hypot(inp.rates_frd_rad_s[0], inp.rates_frd_rad_s[1]) > rot_limit:
            return False
        return self._ground_contact.state
