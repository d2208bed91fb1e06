"""Whole-vehicle scenarios in simulated time: what a MAVSDK/MAVROS user would see (reference 11.4, 4.3, 5.5-5.6)."""

from __future__ import annotations

import math
from collections.abc import Callable

import pytest

from sitl_emu.geo import SIH_HOME
from sitl_emu.params.catalog import px4_catalog
from sitl_emu.px4 import LandedState, MavCmd, MavResult, MavState, NavState, Severity, custom_mode, decode_custom_mode
from sitl_emu.types import NAN3, OffboardControlMode, TrajectorySetpoint, VehicleCommand, VehicleSnapshot
from sitl_emu.vehicle.vehicle import Vehicle

NAN = math.nan
S = 1_000_000
POS = OffboardControlMode(position=True)
VEL = OffboardControlMode(velocity=True)


class Flight:
    """A vehicle plus a client: commands, a 20 Hz offboard stream, and a recorder of snapshots and events."""

    def __init__(self, **kw) -> None:
        self.v = Vehicle(**kw)
        self.stream: tuple[OffboardControlMode, TrajectorySetpoint] | None = None
        self.log: list[VehicleSnapshot] = []
        self._next_stream_us = 0

    def cmd(self, command: int, *params: float) -> int | None:
        p = tuple(params) + (NAN,) * (7 - len(params))
        ack = self.v.handle_command(VehicleCommand(command, p))
        return None if ack is None else ack.result

    def set_mode(self, nav: NavState) -> int | None:
        main, sub = decode_custom_mode(custom_mode(nav))
        return self.cmd(MavCmd.DO_SET_MODE, 1 | 128, main, sub)

    def run(self, seconds: float, until: Callable[[VehicleSnapshot], bool] | None = None, every: int = 25) -> None:
        end = self.v.time_us + int(seconds * S)
        n = 0
        while self.v.time_us < end:
            if self.stream is not None and self.v.time_us >= self._next_stream_us:
                self.v.offboard_input(self.stream[0], self.stream[1])
                self._next_stream_us = self.v.time_us + 50_000
            self.v.step()
            n += 1
            if n % every == 0 or until is not None:
                snap = self.v.snapshot()
                self.log.append(snap)
                if until is not None and until(snap):
                    return

    @property
    def snap(self) -> VehicleSnapshot:
        return self.v.snapshot()

    def texts(self) -> list[str]:
        return [e.text for e in self.v.events_after(0)]

    def event_time_s(self, text: str) -> float:
        return next(e.time_us for e in self.v.events_after(0) if e.text == text) / S

    def takeoff(self) -> None:
        self.run(2.5)
        assert self.cmd(MavCmd.COMPONENT_ARM_DISARM, 1.0) == MavResult.ACCEPTED
        assert self.cmd(MavCmd.NAV_TAKEOFF) == MavResult.ACCEPTED
        self.run(14.0)

    def hover_in_offboard(self) -> None:
        self.takeoff()
        z = self.snap.pos_ned_m[2]
        self.stream = (POS, TrajectorySetpoint(position_ned_m=(0.0, 0.0, z)))
        self.run(0.5)
        assert self.set_mode(NavState.OFFBOARD) == MavResult.ACCEPTED
        self.run(2.0)


def _alt(s: VehicleSnapshot) -> float:
    return -s.pos_ned_m[2]


def test_boot_hold_uninit_then_ready() -> None:
    f = Flight()
    f.run(1.0)
    s = f.snap
    assert not s.armed and s.nav_state == NavState.AUTO_LOITER and not s.pre_flight_checks_pass
    assert s.extras["system_status"] == MavState.UNINIT and s.home is None
    f.run(1.1)
    s = f.snap
    assert s.pre_flight_checks_pass and s.extras["system_status"] == MavState.STANDBY and s.home is not None
    ready = [e for e in f.v.events_after(0) if e.text == "Ready for takeoff!"]
    assert len(ready) == 1 and not ready[0].statustext


def test_arming_refused_before_ready_and_in_return() -> None:
    f = Flight()
    f.run(1.0)
    assert f.cmd(MavCmd.COMPONENT_ARM_DISARM, 1.0) == MavResult.TEMPORARILY_REJECTED
    f.run(1.5)
    assert f.cmd(MavCmd.NAV_RETURN_TO_LAUNCH) == MavResult.ACCEPTED  # disarmed: any mode accepted
    assert f.cmd(MavCmd.COMPONENT_ARM_DISARM, 1.0) == MavResult.TEMPORARILY_REJECTED
    assert "Arming denied: Resolve system health failures first" in f.texts()


def test_takeoff_climbs_to_default_altitude_then_holds() -> None:
    f = Flight()
    f.takeoff()
    f.run(6.0)
    s = f.snap
    assert _alt(s) == pytest.approx(2.5, abs=0.1)
    assert s.nav_state == NavState.AUTO_LOITER and s.landed_state == LandedState.IN_AIR
    assert max(-x.vel_ned_m_s[2] for x in f.log) < 1.5 + 0.1
    switch = next(x for x in f.log if x.nav_state == NavState.AUTO_LOITER and x.armed)
    assert 1.5 < _alt(switch) < 2.45  # Hold near the target (NAV_MC_ALT_RAD 0.8 m), climb continues
    texts = f.texts()
    assert "Using default takeoff altitude: 2.5 m" in texts and "Takeoff detected" in texts
    states = [x.landed_state for x in f.log]
    order = [st for i, st in enumerate(states) if i == 0 or states[i - 1] != st]
    assert order == [LandedState.ON_GROUND, LandedState.TAKEOFF, LandedState.IN_AIR]


def test_land_then_disarm_two_seconds_later() -> None:
    f = Flight()
    f.takeoff()
    f.log.clear()
    assert f.cmd(MavCmd.NAV_LAND) == MavResult.ACCEPTED
    f.run(15.0, until=lambda s: not s.armed)
    s = f.snap
    assert not s.armed and s.nav_state == NavState.AUTO_LOITER
    landed_s, disarm_s = f.event_time_s("Landing detected"), f.event_time_s("Disarmed by landing")
    assert disarm_s - landed_s == pytest.approx(2.0, abs=0.05)
    states = [x.landed_state for x in f.log]
    order = [st for i, st in enumerate(states) if i == 0 or states[i - 1] != st]
    assert order == [LandedState.LANDING, LandedState.ON_GROUND]
    assert max(x.vel_ned_m_s[2] for x in f.log) < 0.7 + 0.15  # MPC_LAND_SPEED below 5 m


def test_preflight_auto_disarm_after_11_s() -> None:
    f = Flight()
    f.run(2.5)
    f.cmd(MavCmd.COMPONENT_ARM_DISARM, 1.0)
    f.run(10.9)
    assert f.snap.armed
    f.run(0.2)
    assert not f.snap.armed and "Disarmed by auto preflight disarming" in f.texts()


def test_disarm_refused_in_air_unless_forced() -> None:
    f = Flight()
    f.takeoff()
    assert f.cmd(MavCmd.COMPONENT_ARM_DISARM, 0.0) == MavResult.TEMPORARILY_REJECTED
    assert "Disarming denied: not landed" in f.texts()
    assert f.cmd(MavCmd.COMPONENT_ARM_DISARM, 0.0, 21196) == MavResult.ACCEPTED and not f.snap.armed


def test_offboard_position_step_10_m() -> None:
    f = Flight()
    f.hover_in_offboard()
    z = f.snap.pos_ned_m[2]
    f.stream = (POS, TrajectorySetpoint(position_ned_m=(10.0, 0.0, z)))
    f.run(10.0)
    s = f.snap
    assert s.nav_state == NavState.OFFBOARD and not s.failsafe
    assert math.dist(s.pos_ned_m, (10.0, 0.0, z)) < 0.2
    assert s.landed_state == LandedState.IN_AIR and s.offboard_control == POS


def test_offboard_velocity_tracked() -> None:
    f = Flight()
    f.hover_in_offboard()
    f.stream = (VEL, TrajectorySetpoint(velocity_ned_m_s=(2.0, -1.0, 0.0)))
    f.run(5.0)
    v = f.snap.vel_ned_m_s
    # SIH drag (SIH_KDV) is only cancelled by the velocity integrator (MPC_XY_VEL_I_ACC 0.4): ~85 % after 5 s
    assert v[0] == pytest.approx(2.0, rel=0.2) and v[1] == pytest.approx(-1.0, rel=0.2) and abs(v[2]) < 0.15
    assert math.atan2(v[1], v[0]) == pytest.approx(math.atan2(-1.0, 2.0), abs=0.05)
    f.run(15.0)
    v = f.snap.vel_ned_m_s
    assert v[0] == pytest.approx(2.0, abs=0.1) and v[1] == pytest.approx(-1.0, abs=0.1)


def test_offboard_yaw_to_90_deg() -> None:
    f = Flight()
    f.hover_in_offboard()
    z = f.snap.pos_ned_m[2]
    f.stream = (POS, TrajectorySetpoint(position_ned_m=(0.0, 0.0, z), yaw_rad=math.pi / 2))
    f.run(5.0)
    assert math.degrees(f.snap.euler_rad[2]) == pytest.approx(90.0, abs=2.0)


def test_offboard_loss_returns_then_resumes() -> None:
    f = Flight()
    f.hover_in_offboard()
    keep = f.stream
    f.stream = None
    f.run(0.9)
    assert f.snap.nav_state == NavState.OFFBOARD
    f.run(0.3)
    s = f.snap
    assert s.nav_state == NavState.AUTO_RTL and s.failsafe and s.user_intended_nav_state == NavState.OFFBOARD
    assert s.extras["system_status"] == MavState.CRITICAL and "Failsafe activated" in f.texts()
    f.stream = keep
    f.run(0.2)
    s = f.snap
    assert s.nav_state == NavState.OFFBOARD and not s.failsafe


def test_offboard_takeoff_from_ground() -> None:
    f = Flight()
    f.run(2.5)
    f.stream = (POS, TrajectorySetpoint(position_ned_m=(0.0, 0.0, -3.0)))
    f.run(0.3)
    assert f.set_mode(NavState.OFFBOARD) == MavResult.ACCEPTED
    assert f.cmd(MavCmd.COMPONENT_ARM_DISARM, 1.0) == MavResult.ACCEPTED
    f.run(12.0)
    s = f.snap
    assert _alt(s) == pytest.approx(3.0, abs=0.15) and s.landed_state == LandedState.IN_AIR


def test_offboard_arming_needs_the_stream() -> None:
    f = Flight()
    f.run(2.5)
    assert f.set_mode(NavState.OFFBOARD) == MavResult.ACCEPTED
    assert f.cmd(MavCmd.COMPONENT_ARM_DISARM, 1.0) == MavResult.TEMPORARILY_REJECTED


@pytest.mark.slow
def test_return_lands_at_home_and_disarms() -> None:
    f = Flight()
    f.hover_in_offboard()
    z = f.snap.pos_ned_m[2]
    f.stream = (POS, TrajectorySetpoint(position_ned_m=(15.0, 10.0, z)))
    f.run(8.0)
    f.stream = None
    assert f.cmd(MavCmd.NAV_RETURN_TO_LAUNCH) == MavResult.ACCEPTED and "Returning to launch" in f.texts()
    f.log.clear()
    f.run(90.0, until=lambda s: not s.armed)
    s = f.snap
    assert not s.armed and "Disarmed by landing" in f.texts()
    assert math.hypot(s.pos_ned_m[0], s.pos_ned_m[1]) < 1.0
    assert LandedState.LANDING in {x.landed_state for x in f.log}


def test_reboot_command_resets_at_next_step() -> None:
    f = Flight()
    f.run(3.0)
    assert f.cmd(MavCmd.PREFLIGHT_REBOOT_SHUTDOWN, 1.0) == MavResult.ACCEPTED
    assert f.v.time_us == 3 * S
    f.v.step()
    assert f.v.time_us == 0 and f.snap.nav_state == NavState.AUTO_LOITER and not f.snap.pre_flight_checks_pass


def test_report_joins_the_event_stream() -> None:
    f = Flight()
    f.run(2.1)
    last = f.v.events_after(0)[-1].seq
    f.v.report(Severity.WARNING, "mavlink", "SET_POSITION_TARGET_LOCAL_NED invalid")
    new = f.v.events_after(last)
    assert [e.text for e in new] == ["SET_POSITION_TARGET_LOCAL_NED invalid"] and new[0].seq == last + 1


def test_snapshot_local_setpoint_and_geo() -> None:
    f = Flight()
    f.takeoff()
    s = f.snap
    assert s.local_setpoint is not None and s.local_setpoint.position_ned_m != NAN3
    assert s.alt_amsl_m == pytest.approx(489.4 - s.pos_ned_m[2])
    assert s.home is not None and s.home.alt_amsl_m == pytest.approx(489.4, abs=0.01)


def test_the_vehicle_starts_where_px4s_sih_does() -> None:
    """SIH_LOC_LAT0 / LON0 / H0 as PX4 reports them (params/px4_params.csv, from ../shared/reference/
    px4-params.json: H0 489.4 m) are the default home, so every AMSL altitude and RTL text matches PX4's."""
    recorded = px4_catalog().px4_defaults
    f = Flight()
    f.run(2.5)
    home = f.snap.home
    assert home is not None
    assert (home.lat_deg, home.lon_deg) == pytest.approx((recorded["SIH_LOC_LAT0"], recorded["SIH_LOC_LON0"]),
                                                         abs=1e-6)
    assert home.alt_amsl_m == pytest.approx(recorded["SIH_LOC_H0"], abs=0.01) == pytest.approx(489.4, abs=0.01)
    assert tuple(f.v.params.get(f"SIH_LOC_{k}") for k in ("LAT0", "LON0", "H0")) == SIH_HOME


def test_takeoff_command_before_arming_keeps_its_altitude() -> None:
    f = Flight()
    f.run(2.5)
    assert f.cmd(MavCmd.NAV_TAKEOFF, NAN, NAN, NAN, NAN, NAN, NAN, 489.4 + 4.0) == MavResult.ACCEPTED  # param7 AMSL
    f.run(1.0)
    assert f.snap.nav_state == NavState.AUTO_TAKEOFF and not f.snap.armed
    assert f.cmd(MavCmd.COMPONENT_ARM_DISARM, 1.0) == MavResult.ACCEPTED  # as pxh> commander takeoff: takeoff, then arm
    f.run(20.0)
    assert _alt(f.snap) == pytest.approx(4.0, abs=0.1) and f.snap.nav_state == NavState.AUTO_LOITER
    assert "Using default takeoff altitude: 2.5 m" not in f.texts()


def test_default_takeoff_text_once_at_arming() -> None:
    f = Flight()
    f.run(2.5)
    f.cmd(MavCmd.NAV_TAKEOFF)
    f.run(1.0)
    f.cmd(MavCmd.COMPONENT_ARM_DISARM, 1.0)
    f.run(3.0)
    assert f.texts().count("Using default takeoff altitude: 2.5 m") == 1
    assert f.event_time_s("Using default takeoff altitude: 2.5 m") >= f.event_time_s("Armed by external command")


def test_reposition_flies_to_the_point_in_hold() -> None:
    from sitl_emu.geo import ned_to_global

    f = Flight()
    f.takeoff()
    lat, lon, alt = ned_to_global(f.v.ref, (8.0, -6.0, -5.0))
    assert f.cmd(MavCmd.DO_REPOSITION, -1.0, 1.0, NAN, NAN, lat, lon, alt) == MavResult.ACCEPTED
    f.run(15.0)
    s = f.snap
    assert s.nav_state == NavState.AUTO_LOITER
    assert math.dist(s.pos_ned_m, (8.0, -6.0, -5.0)) < 0.3



def test_reposition_without_yaw_faces_the_target() -> None:
    """PX4 passes a NaN yaw (param4) on; with MPC_YAW_MODE 0 the vehicle turns to face where it flies."""
    from sitl_emu.geo import ned_to_global

    f = Flight()
    f.takeoff()
    lat, lon, alt = ned_to_global(f.v.ref, (40.0, 30.0, -2.5))
    assert f.cmd(MavCmd.DO_REPOSITION, -1.0, 1.0, NAN, NAN, lat, lon, alt) == MavResult.ACCEPTED
    f.run(25.0)
    assert math.degrees(f.snap.euler_rad[2]) == pytest.approx(math.degrees(math.atan2(30.0, 40.0)), abs=3.0)

def test_change_altitude_in_hold() -> None:
    f = Flight()
    f.takeoff()
    assert f.cmd(MavCmd.DO_CHANGE_ALTITUDE, 489.4 + 6.0, 0.0) == MavResult.ACCEPTED  # MAV_FRAME_GLOBAL: AMSL
    f.run(10.0)
    s = f.snap
    assert _alt(s) == pytest.approx(6.0, abs=0.15) and math.hypot(s.pos_ned_m[0], s.pos_ned_m[1]) < 0.3
    f.set_mode(NavState.AUTO_RTL)
    assert f.cmd(MavCmd.DO_CHANGE_ALTITUDE, 490.0, 0.0) == MavResult.DENIED  # only in Hold


def test_events_after_returns_the_newer_events_of_the_kept_history() -> None:
    from sitl_emu.px4 import Severity

    v = Vehicle()
    first = v.last_event_seq
    for i in range(1100):
        v.report(Severity.INFO, "test", f"event {i}")
    last = v.last_event_seq
    kept = v.events_after(first)
    assert len(kept) == 1000 and kept[-1].text == "event 1099" and kept[0].seq == last - 999
    assert [e.text for e in v.events_after(last - 2)] == ["event 1098", "event 1099"]
    assert v.events_after(last) == [] and v.events_after(last + 5) == []
