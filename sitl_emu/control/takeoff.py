"""Smooth takeoff handling after PX4's TakeoffHandling (src/modules/mc_pos_control/Takeoff/Takeoff.cpp).

disarmed -> spoolup (COM_SPOOLUP_TIME after arming) -> ready_for_takeoff -> rampup (MPC_TKO_RAMP_T, when a takeoff
is wanted) -> flight; back to ready_for_takeoff when landed. During the ramp the upward velocity limit rises from
-g / MPC_Z_VEL_P_ACC (which still pushes down) to the desired climb rate. Before the ramp the position controller
commands idle thrust; the tilt limit is MPC_TILTMAX_LND until flight (MulticopterPositionControl.cpp).
"""

from __future__ import annotations

from enum import IntEnum
from typing import Final

G: Final = 9.80665


class TakeoffState(IntEnum):
    """takeoff_status.takeoff_state numbering (msg/TakeoffStatus.msg)."""

    UNINITIALIZED = 0
    DISARMED = 1
    SPOOLUP = 2
    READY_FOR_TAKEOFF = 3
    RAMPUP = 4
    FLIGHT = 5


def before_ramp(state: TakeoffState) -> bool:
    """PX4's `takeoff_state < rampup` (disarmed, spooling up or ready for takeoff), written with `is`: compiled, an
    IntEnum's `<` or `==` is Python's rich comparison (ARCHITECTURE.md, On the tick path)."""
    return state is not TakeoffState.RAMPUP and state is not TakeoffState.FLIGHT


class TakeoffHandling:
    def __init__(self, spoolup_time_s: float = 1.0, ramp_time_s: float = 3.0, vel_p_acc_z: float = 4.0) -> None:
        self.state = TakeoffState.DISARMED
        self.configure(spoolup_time_s, ramp_time_s, vel_p_acc_z)
        self._armed_since_us: int | None = None
        self._ramp_progress = 0.0

    def configure(self, spoolup_time_s: float, ramp_time_s: float, vel_p_acc_z: float) -> None:
        self.spoolup_time_s = spoolup_time_s
        self.ramp_time_s = ramp_time_s
        self.ramp_vz_init = -G / max(vel_p_acc_z, 0.01)  # generateInitialRampValue

    def update_state(self, armed: bool, landed: bool, want_takeoff: bool, now_us: int,
                     skip_takeoff: bool = False) -> TakeoffState:
        """updateTakeoffState: advance the state machine (it may pass several states in one call, as PX4's does)."""
        st = self.state
        if st is TakeoffState.FLIGHT and armed and not landed and self._armed_since_us is not None:
            return st  # the usual case in the air: nothing below would change it
        if not armed:
            self._armed_since_us = None
            self.state = TakeoffState.DISARMED
            return self.state
        if self._armed_since_us is None:
            self._armed_since_us = now_us
        if st <= TakeoffState.DISARMED:
            st = TakeoffState.SPOOLUP
        if st is TakeoffState.SPOOLUP and now_us - self._armed_since_us >= self.spoolup_time_s * 1e6:
            st = TakeoffState.READY_FOR_TAKEOFF
        if st is TakeoffState.READY_FOR_TAKEOFF and want_takeoff:
            st = TakeoffState.RAMPUP
            self._ramp_progress = 0.0
        if st is TakeoffState.RAMPUP and self._ramp_progress >= 1.0:
            st = TakeoffState.FLIGHT
        if st is TakeoffState.FLIGHT and landed:
            st = TakeoffState.READY_FOR_TAKEOFF
        if skip_takeoff:
            st = TakeoffState.FLIGHT
        self.state = st
        return st

    def update_ramp(self, dt_s: float, desired_vz_up: float) -> float:
        """updateRamp: the upward velocity limit for this cycle (m/s, positive up)."""
        if self.state is TakeoffState.FLIGHT:
            return desired_vz_up
        if before_ramp(self.state):
            return self.ramp_vz_init
        if self.state is TakeoffState.RAMPUP:
            if self.ramp_time_s > dt_s:
                self._ramp_progress += dt_s / self.ramp_time_s
            else:
                self._ramp_progress = 1.0
            if self._ramp_progress < 1.0:
                return self.ramp_vz_init + self._ramp_progress * (desired_vz_up - self.ramp_vz_init)
        return desired_vz_up

