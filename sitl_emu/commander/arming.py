"""Mode requirements, "can run" and "can arm" for a multicopter, as PX4's health and arming checks decide them.

Pure functions of a `CheckInputs` snapshot. Sources:
- which mode needs what: src/modules/commander/ModeUtil/mode_requirements.cpp (rotary-wing branch)
- how a failed requirement clears the can-run/arming bits and the reason texts:
  src/modules/commander/HealthAndArmingChecks/checks/modeCheck.cpp
- offboard signal freshness: HealthAndArmingChecks/checks/offboardCheck.cpp (timestamp + COM_OF_LOSS_T > now)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

from sitl_emu.px4 import NavState


class Req:
    """One bit per mode requirement (failsafe_flags.mode_req_*); plain ints, as enum.Flag is slow per step."""

    NONE: Final = 0
    ATTITUDE: Final = 1  # angular velocity + attitude
    POSITION: Final = 2  # local (relaxed or not), global position and local altitude
    HOME: Final = 4
    MISSION: Final = 8
    OFFBOARD: Final = 16
    MANUAL: Final = 32
    PREVENT_ARMING: Final = 64


_A, _P, _M = Req.ATTITUDE, Req.POSITION, Req.MANUAL

# mode_requirements.cpp, multicopter (ROTARY_WING) branch
_REQUIREMENTS: Final[dict[NavState, int]] = {
    NavState.MANUAL: _M,
    NavState.ALTCTL: _A | _P | _M,
    NavState.ALTITUDE_CRUISE: _A | _P | _M,
    NavState.POSCTL: _A | _P | _M,
    NavState.POSITION_SLOW: _A | _P | _M,
    NavState.AUTO_MISSION: _A | _P | Req.MISSION,
    NavState.AUTO_LOITER: _A | _P,
    NavState.GUIDED_COURSE: _A | _P,
    NavState.AUTO_RTL: _A | _P | Req.HOME | Req.PREVENT_ARMING,
    NavState.ACRO: _M,
    NavState.DESCEND: _A | Req.PREVENT_ARMING,
    NavState.TERMINATION: Req.PREVENT_ARMING,
    NavState.OFFBOARD: _A | Req.OFFBOARD,
    NavState.STAB: _A | _M,
    NavState.AUTO_TAKEOFF: _A | _P,
    NavState.AUTO_LAND: _A | _P | Req.PREVENT_ARMING,
    NavState.AUTO_FOLLOW_TARGET: _A | _P | Req.PREVENT_ARMING,
    NavState.AUTO_PRECLAND: _A | _P | Req.PREVENT_ARMING,
    NavState.ORBIT: _A | _P | Req.PREVENT_ARMING,
    NavState.AUTO_VTOL_TAKEOFF: _A | _P,
}

# The reasons modeCheck.cpp reports (as events) for each failed requirement, in its order.
_REASONS: Final[tuple[tuple[int, str], ...]] = (
    (Req.ATTITUDE, "No valid attitude estimate"),
    (Req.POSITION, "Navigation error: No valid position estimate"),
    (Req.MISSION, "No valid mission available"),
    (Req.HOME, "Home position not set"),
    (Req.MANUAL, "No manual control input"),
    (Req.OFFBOARD, "No offboard signal"),
)


@dataclass(slots=True)
class CheckInputs:
    """What the checks look at, at one instant.

    Made every commander cycle; read-only by convention (see ARCHITECTURE.md, On the tick path)."""

    estimator_ready: bool  # attitude, local/global position and altitude valid (SITL: after the warm-up)
    home_valid: bool
    offboard_signal: bool  # an offboard_control_mode with a setpoint kind, younger than COM_OF_LOSS_T
    manual_control: bool = False  # RC or MAVLink joystick present: never in SITL without a joystick
    mission_valid: bool = False  # a valid mission is stored (navigator/mission_store.py MissionStore.mission_valid)
    position_lost: bool = False  # no horizontal position (GPS off past EKF2_NOAID_TOUT: vehicle/faults.py)

    def __init__(self, estimator_ready: bool, home_valid: bool, offboard_signal: bool, manual_control: bool = False,
                 mission_valid: bool = False, position_lost: bool = False) -> None:
        self.estimator_ready = estimator_ready
        self.home_valid = home_valid
        self.offboard_signal = offboard_signal
        self.manual_control = manual_control
        self.mission_valid = mission_valid
        self.position_lost = position_lost

    def available(self) -> int:
        """The requirement bits these inputs satisfy."""
        have = (Req.ATTITUDE | Req.POSITION) if self.estimator_ready else Req.NONE
        if self.position_lost:
            have &= ~Req.POSITION
        if self.home_valid:
            have |= Req.HOME
        if self.mission_valid:
            have |= Req.MISSION
        if self.offboard_signal:
            have |= Req.OFFBOARD
        if self.manual_control:
            have |= Req.MANUAL
        return have


def requirements(nav_state: NavState) -> int:
    return _REQUIREMENTS.get(nav_state, Req.NONE)


def mode_prevents_arming(nav_state: NavState) -> bool:
    return bool(requirements(nav_state) & Req.PREVENT_ARMING)


def missing(nav_state: NavState, c: CheckInputs) -> int:
    """The requirements of nav_state that are not met now (PREVENT_ARMING excluded)."""
    return requirements(nav_state) & ~(c.available() | Req.PREVENT_ARMING)


def can_run(nav_state: NavState, c: CheckInputs, ignoring: int = Req.NONE) -> bool:
    """True if nav_state's requirements are met (HealthAndArmingChecks::canRun), leaving out the `ignoring` bits."""
    return not (missing(nav_state, c) & ~ignoring)


def arming_failure(nav_state: NavState, c: CheckInputs, armed: bool = False) -> str | None:
    """None if arming is allowed in nav_state, else the first failing check's text (canArm is False).

    While armed the "mode prevents arming" check is skipped (modeCheck.cpp), so vehicle_status.pre_flight_checks_pass
    stays true when flying in Return or Land."""
    if not c.estimator_ready:
        # Every arming check needs the estimator (ekf2 not ready: attitude/position invalid).
        return "No valid attitude estimate"
    if not armed and mode_prevents_arming(nav_state):
        return "Mode not suitable for arming"
    gaps = missing(nav_state, c)
    for req, text in _REASONS:
        if req & gaps:
            return text
    return None


def can_arm(nav_state: NavState, c: CheckInputs, armed: bool = False) -> bool:
    return arming_failure(nav_state, c, armed) is None


def modes_requiring(req: int) -> int:
    """The nav_states (one bit each, as failsafe_flags.mode_req_* hold them) whose requirements include `req`."""
    return sum(1 << int(nav) for nav, r in _REQUIREMENTS.items() if r & req)
