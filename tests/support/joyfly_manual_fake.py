"""A fake PX4 that also takes MANUAL_CONTROL, for joyfly's --control position/altitude session tests. Kinematic, and
only the rules a manual client meets (../notes/px4_manual_spec.md; the reference ../px4-manual cases):

- MANUAL_CONTROL to target 0 or 1 is the RC, present while it keeps coming (lost 0.5 s after the last one);
- DO_SET_MODE to POSCTL/ALTCTL: always accepted disarmed, armed only with the RC present;
- ARM in POSCTL/ALTCTL: "Resolve system health failures first" without RC, "throttle not in safe position" above
  0.2 (z > 600); STANDBY in these modes only with RC;
- POSCTL/ALTCTL fly the sticks: x north and y east at up to 5 m/s (heading north), the throttle climbs at up to
  3 m/s and takes off above z 650, centred sticks hold;
- RC lost while armed (not in Land/Return): "Failsafe activated: entering Hold for 5 seconds", Hold, then Return;
- in Hold/Return/Land sticks on the move take over to POSCTL ("Pilot took over using sticks"), by PX4's rule
  (ManualControl.cpp, MovingDiff): on some axis the change per second, low-passed with tau 0.05 s, above
  MAN_OVERRIDE_SPD (1 /s), after at least 3 consecutive changes of one sign; a held or a single jump never does.
"""

from __future__ import annotations

import math
from typing import Any

from support.joyfly_fakes import LAND, LOITER, RTL, FakeVehicle

POSCTL = 3 << 16
ALTCTL = 2 << 16
MANUAL_MODES = (POSCTL, ALTCTL)
RC_LOSS_S = 0.5


class ManualFakeVehicle(FakeVehicle):
    """FakeVehicle plus MANUAL_CONTROL. `manual` is the last (x, y, z, r) received, `manual_time` when."""

    def __post_init__(self) -> None:
        super().__post_init__()
        self.manual: tuple[int, int, int, int] = (0, 0, 500, 0)
        self.manual_time = -math.inf
        self.sticks_moving = False
        self._rate = [0.0, 0.0, 0.0, 0.0]  # low-passed change per second of x, y, z, r (in -1..1 units)
        self._same_sign = [0, 0, 0, 0]
        self.failsafe_since: float | None = None
        self.wrong_targets = 0

    def step(self, now_s: float) -> None:
        """With `speak` False the link is dead both ways but the vehicle flies on (its RC-loss failsafe acts)."""
        if self.speak:
            super().step(now_s)
            return
        dt, self.now = now_s - self.now, now_s
        while self.transport.read(0.0):
            pass  # lost on the way
        self._modes()
        self._move(dt)

    def rc_ok(self) -> bool:
        return self.now - self.manual_time < RC_LOSS_S

    def _handle(self, msg: Any) -> None:
        if msg.get_type() != "MANUAL_CONTROL":
            super()._handle(msg)
            return
        self.log.append((self.now, "MANUAL", msg))
        if msg.target not in (0, 1):
            self.wrong_targets += 1
            return
        self._moving_diff((msg.x, msg.y, msg.z, msg.r))
        self.manual, self.manual_time = (msg.x, msg.y, msg.z, msg.r), self.now

    def _moving_diff(self, sample: tuple[int, int, int, int]) -> None:
        dt = self.now - self.manual_time
        if not 0.0 < dt < RC_LOSS_S:
            self._rate, self._same_sign = [0.0] * 4, [0] * 4
            return
        alpha = dt / (0.05 + dt)
        for i, (new, old) in enumerate(zip(sample, self.manual, strict=True)):
            step = (new - old) / (500.0 if i == 2 else 1000.0)
            self._rate[i] += alpha * (step / dt - self._rate[i])
            if step:
                same = self._same_sign[i] > 0 if step > 0 else self._same_sign[i] < 0
                self._same_sign[i] = self._same_sign[i] + (1 if step > 0 else -1) if same else (1 if step > 0 else -1)
        self.sticks_moving = any(abs(r) > 1.0 and abs(c) >= 3 for r, c in zip(self._rate, self._same_sign,
                                                                               strict=True))

    def _set_mode(self, msg: Any, mode: int) -> None:
        if mode in MANUAL_MODES and self.armed and not self.rc_ok():
            self._ack(msg, 1)
            self._text(2, "Switching to Position is currently not available")
            return
        self.failsafe_since = None  # a mode change ends the RC-loss failsafe
        super()._set_mode(msg, mode)

    def _arm_command(self, msg: Any) -> None:
        if round(msg.param1) == 1 and self.custom_mode in MANUAL_MODES:
            if not self.rc_ok():
                self._text(2, "Arming denied: Resolve system health failures first")
                self._ack(msg, 1)
                return
            if self.manual[2] > 600:
                self._text(2, "Arming denied: throttle not in safe position")
                self._ack(msg, 1)
                return
        super()._arm_command(msg)

    def _system_status(self) -> int:
        if not self.armed and self.custom_mode in MANUAL_MODES and not self.rc_ok():
            return 0  # UNINIT: the arming checks fail without RC
        return 5 if self.failsafe_since is not None and self.armed else super()._system_status()

    def _modes(self) -> None:
        self._rc_failsafe()
        self._takeover()
        super()._modes()

    def _rc_failsafe(self) -> None:
        if not self.armed:
            self.failsafe_since = None
            return
        if self.failsafe_since is None and not self.rc_ok() and self.custom_mode not in (LAND, RTL):
            self.failsafe_since = self.now
            self.custom_mode = LOITER
            self._text(2, "Failsafe activated: entering Hold for 5 seconds")
        elif self.failsafe_since is not None and self.now - self.failsafe_since > 5.0 and self.custom_mode == LOITER:
            self.custom_mode = RTL
            self._text(2, "Failsafe activated")

    def _takeover(self) -> None:
        if self.armed and self.rc_ok() and self.sticks_moving and self.custom_mode in (LOITER, RTL, LAND):
            self.custom_mode = self.intention = POSCTL
            self.failsafe_since = None
            self._text(6, "Pilot took over using sticks")

    def _target_velocity(self) -> list[float]:
        if not (self.armed and self.custom_mode in MANUAL_MODES):
            return super()._target_velocity()
        if not self.rc_ok():
            return [0.0, 0.0, 0.0]
        x, y, z, _ = self.manual
        throttle = z / 500 - 1
        climb = 0.0 if abs(throttle) < 0.1 else throttle * (3.0 if throttle > 0 else 1.5)
        if self.landed and throttle <= 0.3:
            climb = 0.0
        return [x / 1000 * 5.0, y / 1000 * 5.0, -climb]
