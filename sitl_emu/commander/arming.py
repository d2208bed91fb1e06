"""Mode requirements, "can run" and "can arm" for a multicopter, as PX4's health and arming checks decide them.

Pure functions of a `CheckInputs` snapshot. Sources:
- which mode needs what: src/modules/commander/ModeUtil/mode_requirements.cpp getModeRequirements (the flags
  failsafe_flags.mode_req_*, multicopter (ROTARY_WING) branch); one `Req` bit per flag;
- what the estimator provides: HealthAndArmingChecks/checks/estimatorCheck.cpp setModeRequirementFlags (the
  failsafe_flags *_invalid bits), modelled by `estimate_valid` from what the emulator knows;
- how a failed requirement clears the can-run/arming bits, in which order, with which texts:
  HealthAndArmingChecks/checks/modeCheck.cpp (the health report, commander/health_report.py, sends them as events);
- offboard signal freshness and the estimate it needs: HealthAndArmingChecks/checks/offboardCheck.cpp.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

from sitl_emu.px4 import NavState
from sitl_emu.types import OffboardControlMode


class Req:
    """One bit per mode requirement (failsafe_flags.mode_req_*); plain ints, as enum.Flag is slow per step.

    mode_req_global_position_relaxed (fixed-wing only), mode_req_other (external modes) and mode_req_not_possible
    (rover) are set for no multicopter mode, so they have no bit here."""

    NONE: Final = 0
    ANGULAR_VELOCITY: Final = 1
    ATTITUDE: Final = 2
    LOCAL_ALT: Final = 4
    LOCAL_POSITION: Final = 8
    LOCAL_POSITION_RELAXED: Final = 16  # no accuracy limit (COM_POS_FS_EPH): the pilot corrects the drift
    GLOBAL_POSITION: Final = 32
    MISSION: Final = 64
    OFFBOARD: Final = 128
    HOME: Final = 256
    MANUAL: Final = 512
    PREVENT_ARMING: Final = 1024
    WIND_AND_FLIGHT_TIME: Final = 2048  # COM_WIND_MAX / COM_FLT_TIME_MAX: neither limit is simulated, always met


_W, _A = Req.ANGULAR_VELOCITY, Req.ANGULAR_VELOCITY | Req.ATTITUDE
_ALT, _LP, _LPR, _GP = Req.LOCAL_ALT, Req.LOCAL_POSITION, Req.LOCAL_POSITION_RELAXED, Req.GLOBAL_POSITION
_M, _P, _WF = Req.MANUAL, Req.PREVENT_ARMING, Req.WIND_AND_FLIGHT_TIME

# mode_requirements.cpp getModeRequirements, multicopter branch (MANUAL_PARKING is a rover mode)
_REQUIREMENTS: Final[dict[NavState, int]] = {
    NavState.MANUAL: _M,
    NavState.ALTCTL: _A | _ALT | _M,
    NavState.ALTITUDE_CRUISE: _A | _ALT | _M,
    NavState.POSCTL: _A | _ALT | _LPR | _M,
    NavState.POSITION_SLOW: _A | _ALT | _LPR | _M,
    NavState.AUTO_MISSION: _A | _GP | _LP | _ALT | Req.MISSION | _WF,
    NavState.AUTO_LOITER: _A | _GP | _LP | _ALT | _WF,
    NavState.GUIDED_COURSE: _A | _ALT | _WF | _LPR,
    NavState.AUTO_RTL: _A | _GP | _LP | _ALT | Req.HOME | _P,
    NavState.ACRO: _W | _M,
    NavState.DESCEND: _A | _P,
    NavState.TERMINATION: _P,
    NavState.OFFBOARD: _A | Req.OFFBOARD,
    NavState.STAB: _A | _M,
    NavState.AUTO_TAKEOFF: _A | _ALT | _LP,
    NavState.AUTO_LAND: _A | _ALT | _LPR | _P,
    NavState.AUTO_FOLLOW_TARGET: _A | _LP | _ALT | _P | _WF,
    NavState.AUTO_PRECLAND: _A | _LP | _ALT | _P,
    NavState.ORBIT: _A | _LP | _ALT | _P | _WF,
    NavState.AUTO_VTOL_TAKEOFF: _A | _ALT | _LP,
}

# modeCheck.cpp's checks in its order (after "Mode not suitable for arming"): the requirement bits each one looks at
# and its text. The local position check covers the strict and the relaxed requirement.
_REASONS: Final[tuple[tuple[int, str], ...]] = (
    (Req.ANGULAR_VELOCITY, "Angular velocity not valid"),
    (Req.ATTITUDE, "No valid attitude estimate"),
    (Req.LOCAL_POSITION | Req.LOCAL_POSITION_RELAXED, "No valid local position estimate"),
    (Req.GLOBAL_POSITION, "No valid global position estimate"),
    (Req.LOCAL_ALT, "No valid altitude estimate"),
    (Req.MISSION, "No valid mission available"),
    (Req.OFFBOARD, "No offboard signal"),
    (Req.HOME, "Home position not set"),
    (Req.MANUAL, "No manual control input"),
)
PREVENTS_ARMING_TEXT: Final = "Mode not suitable for arming"
_POSITION: Final = Req.LOCAL_POSITION | Req.LOCAL_POSITION_RELAXED | Req.GLOBAL_POSITION


def estimate_valid(estimator_ready: bool, position_lost: bool) -> int:
    """The Req bits the estimate satisfies (estimatorCheck.cpp setModeRequirementFlags, inverted *_invalid flags).

    The simulated gyro gives an angular velocity from boot. Until the estimator's warm-up ends there is no attitude,
    altitude or position. Afterwards a lost GPS (dead reckoning past EKF2_NOAID_TOUT, vehicle/faults.py) takes away
    the local position (strict and relaxed: lpos.xy_valid is false) and the global position; the barometer keeps
    the altitude and the IMU the attitude."""
    if not estimator_ready:
        return Req.ANGULAR_VELOCITY
    have = Req.ANGULAR_VELOCITY | Req.ATTITUDE | Req.LOCAL_ALT
    return have if position_lost else have | _POSITION


@dataclass(slots=True)
class CheckInputs:
    """What the checks look at, at one instant.

    Made every commander cycle; read-only by convention (see ARCHITECTURE.md, On the tick path)."""

    estimator_ready: bool  # the estimator's warm-up is over (SITL: a fixed delay after boot)
    home_valid: bool
    offboard_signal: bool  # offboardCheck.cpp: a fresh offboard_control_mode whose setpoints the estimate supports
    manual_control: bool = False  # RC or MAVLink joystick present: never in SITL without a joystick
    mission_valid: bool = False  # a valid mission is stored (navigator/mission_store.py MissionStore.mission_valid)
    position_lost: bool = False  # no horizontal position (GPS off past EKF2_NOAID_TOUT: vehicle/faults.py)
    mission_required: bool = False  # COM_ARM_MIS_REQ: arming in any mode needs a valid mission

    def __init__(self, estimator_ready: bool, home_valid: bool, offboard_signal: bool, manual_control: bool = False,
                 mission_valid: bool = False, position_lost: bool = False, mission_required: bool = False) -> None:
        self.estimator_ready = estimator_ready
        self.home_valid = home_valid
        self.offboard_signal = offboard_signal
        self.manual_control = manual_control
        self.mission_valid = mission_valid
        self.position_lost = position_lost
        self.mission_required = mission_required

    def available(self) -> int:
        """The requirement bits these inputs satisfy."""
        have = estimate_valid(self.estimator_ready, self.position_lost) | Req.WIND_AND_FLIGHT_TIME
        if self.home_valid:
            have |= Req.HOME
        if self.mission_valid:
            have |= Req.MISSION
        if self.offboard_signal:
            have |= Req.OFFBOARD
        if self.manual_control:
            have |= Req.MANUAL
        return have


class CheckInputsCache:
    """The last CheckInputs, made again only when one of its values changed: they are read-only, so the commander
    cycles share one while nothing changes (ARCHITECTURE.md, On the tick path)."""

    def __init__(self) -> None:
        self._key = (False, False, False, False, False, False, False)
        self._inputs = CheckInputs(False, False, False)

    def of(self, estimator_ready: bool, home_valid: bool, offboard_signal: bool, manual_control: bool,
           mission_valid: bool, position_lost: bool, mission_required: bool) -> CheckInputs:
        key = (estimator_ready, home_valid, offboard_signal, manual_control, mission_valid, position_lost,
               mission_required)
        if key != self._key:
            self._key = key
            self._inputs = CheckInputs(estimator_ready, home_valid, offboard_signal, manual_control, mission_valid,
                                       position_lost, mission_required)
        return self._inputs


def offboard_available(mode: OffboardControlMode, estimate: int) -> bool:
    """offboardCheck.cpp, for a fresh signal of these setpoint kinds: the estimate they need is there (a local
    position for positions, a local velocity (valid with the position here) for velocities, an attitude for
    accelerations)."""
    if mode.position or mode.velocity:
        return bool(estimate & Req.LOCAL_POSITION)
    return not mode.acceleration or bool(estimate & Req.ATTITUDE)


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
    """None if arming is allowed in nav_state (canArm), else the text of the first of modeCheck.cpp's checks that
    fails for it. A check clears the arming bits of the modes requiring what it misses, and nothing else: so with
    the estimator still warming up, Manual and Acro can arm with sticks (they need no attitude estimate).

    While armed the "mode prevents arming" check is skipped (modeCheck.cpp), so vehicle_status.pre_flight_checks_pass
    stays true when flying in Return or Land. COM_ARM_MIS_REQ 1 makes the mission check fail arming in every mode
    while no valid mission is stored (only Mission itself cannot run without one)."""
    if not armed and mode_prevents_arming(nav_state):
        return PREVENTS_ARMING_TEXT
    gaps = missing(nav_state, c) | missing_for_arming(c)
    if gaps:
        for req, text in _REASONS:
            if req & gaps:
                return text
    return None


def missing_for_arming(c: CheckInputs) -> int:
    """What arming needs beyond the mode's own requirements: a valid mission when COM_ARM_MIS_REQ says so
    (modeCheck.cpp: mission_required_modes becomes NavModes::All for the arming check)."""
    return Req.MISSION if c.mission_required and not c.mission_valid else Req.NONE


def can_arm(nav_state: NavState, c: CheckInputs, armed: bool = False) -> bool:
    return arming_failure(nav_state, c, armed) is None


def modes_requiring(req: int) -> int:
    """The nav_states (one bit each, as failsafe_flags.mode_req_* hold them) whose requirements include any of
    `req`'s bits."""
    return sum(1 << int(nav) for nav, r in _REQUIREMENTS.items() if r & req)
