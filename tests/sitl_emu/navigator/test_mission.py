"""AUTO.MISSION item by item on a Vehicle (no MAVLink): pausing and resuming, jumping with MISSION_SET_CURRENT, and
each navigator item PX4 flies (after src/modules/navigator/mission_base.cpp, mission.cpp, mission_block.cpp)."""

from __future__ import annotations

import math

import pytest
from support.mission_flight import (
    AMSL,
    DELAY,
    DO_CHANGE_SPEED,
    DO_JUMP,
    LAND,
    LOITER_TIME,
    LOITER_UNLIM,
    ROI_LOCATION,
    ROI_NONE,
    TAKEOFF_ITEM,
    Flight,
    do,
    wp,
)

from sitl_emu.navigator.mission_store import (
    MISSION_STATE_ACTIVE,
    MISSION_STATE_COMPLETE,
    MISSION_STATE_PAUSED,
    PLAN_MISSION,
)
from sitl_emu.px4 import MavCmd, MavResult, NavState


@pytest.mark.slow
def test_hold_pauses_and_auto_mission_resumes_at_the_current_item() -> None:
    f = Flight([TAKEOFF_ITEM, wp(25, 0), wp(25, 25), wp(0, 25)])
    f.start()
    f.run_until(lambda: f.store.current_seq == 2)
    assert f.command(MavCmd.DO_SET_MODE, 1, 4, 3) == MavResult.ACCEPTED  # AUTO.LOITER
    f.run_until(lambda: f.speed < 0.2, 10.0)
    assert f.store.mission_state(False) == MISSION_STATE_PAUSED and f.store.current_seq == 2
    here = f.v.snapshot().pos_ned_m
    f.v.run_for(2.0)
    assert f.at(here[0], here[1]) < 0.3  # holds
    assert f.command(MavCmd.DO_SET_MODE, 1, 4, 4) == MavResult.ACCEPTED  # AUTO.MISSION again
    assert f.store.mission_state(True) == MISSION_STATE_ACTIVE
    f.run_until(lambda: f.store.finished)
    assert [s for s, _ in f.reached] == [0, 1, 2, 3] and f.texts.count("Executing Mission") == 2
    f.v.run_for(6.0)  # reached 10 m before (NAV_ACC_RAD); the end loiters at the last waypoint
    assert f.store.mission_state(True) == MISSION_STATE_COMPLETE and f.at(0, 25) < 1.0
    assert "Mission finished, loitering" in f.texts


def test_mission_set_current_while_flying_turns_to_that_item() -> None:
    f = Flight([TAKEOFF_ITEM, wp(30, 0), wp(30, 30), wp(0, 30)])
    f.start()
    f.run_until(lambda: f.store.current_seq == 1)
    f.v.run_for(2.0)
    assert f.command(MavCmd.DO_SET_MISSION_CURRENT, 7, 0) == MavResult.FAILED  # no item 7
    assert f.command(MavCmd.DO_SET_MISSION_CURRENT, 3, 0) == MavResult.ACCEPTED  # as MISSION_SET_CURRENT 3
    f.run_until(lambda: f.store.finished)
    assert f.currents == [0, 1, 3] and [s for s, _ in f.reached] == [0, 3]


def test_a_new_upload_while_flying_is_flown_from_its_current_item() -> None:
    f = Flight([TAKEOFF_ITEM, wp(30, 0), wp(30, 30)])
    f.start()
    f.run_until(lambda: f.store.current_seq == 1)
    new = Flight([wp(0, 20), wp(-10, 20)]).store.plan(PLAN_MISSION).items
    f.store.replace(PLAN_MISSION, new, current_seq=1)  # what a completed upload does
    f.run_until(lambda: f.store.finished)
    f.v.run_for(6.0)
    assert f.at(-10, 20) < 1.0 and f.store.seq_reached == 1


def test_waypoint_hold_time_and_loiter_time_wait_there() -> None:
    f = Flight([TAKEOFF_ITEM, wp(8, 0, 5.0, 3.0), wp(0, 0, 5.0, 4.0, cmd=LOITER_TIME), wp(0, 8)])
    f.start()
    f.run_until(lambda: f.store.seq_reached == 3)
    t = dict(f.reached)
    assert t[1] - t[0] >= 3.0 and 4.0 <= t[2] - t[1] < 9.0


def test_loiter_unlimited_is_never_reached() -> None:
    f = Flight([TAKEOFF_ITEM, wp(10, 0, cmd=LOITER_UNLIM), wp(0, 0)])
    f.start()
    f.run_until(lambda: f.store.current_seq == 1)
    f.v.run_for(15.0)
    assert f.store.current_seq == 1 and f.at(10, 0) < 0.5 and f.speed < 0.2


def test_land_item_flies_there_lands_and_disarms() -> None:
    f = Flight([TAKEOFF_ITEM, wp(15, 0), wp(15, 10, 0.0, cmd=LAND)])
    f.start()
    f.run_until(lambda: not f.v.commander.armed, 90.0)
    assert f.at(15, 10) < 1.0
    assert f.texts.index("Landing detected") < f.texts.index("Mission finished, landed") \
        < f.texts.index("Disarmed by landing")


def test_delay_holds_before_the_next_item() -> None:
    f = Flight([TAKEOFF_ITEM, wp(6, 0), do(DELAY, 5.0), wp(0, 0)])
    f.start()
    f.run_until(lambda: f.store.seq_reached == 3)
    t = dict(f.reached)
    assert t[2] - t[1] == pytest.approx(5.0, abs=0.1)


def test_change_speed_limits_the_cruise_speed() -> None:
    f = Flight([TAKEOFF_ITEM, do(DO_CHANGE_SPEED, 1, 2.0, -1), wp(40, 0)])
    f.start()
    f.run_until(lambda: f.store.current_seq == 2)
    peak = 0.0
    while not f.store.finished:
        f.run_until(lambda: True)
        peak = max(peak, f.speed)
    assert 1.8 < peak < 2.2


def test_a_resumed_mission_keeps_the_changed_speed() -> None:
    f = Flight([TAKEOFF_ITEM, do(DO_CHANGE_SPEED, 1, 2.0, -1), wp(20, 0), wp(20, 30)])
    f.start()
    f.run_until(lambda: f.store.current_seq == 3)
    assert f.command(MavCmd.DO_SET_MODE, 1, 4, 3) == MavResult.ACCEPTED  # Hold
    f.run_until(lambda: f.speed < 0.1, 10.0)
    assert f.command(MavCmd.DO_SET_MODE, 1, 4, 4) == MavResult.ACCEPTED  # and on
    peak = 0.0
    while not f.store.finished:
        f.run_until(lambda: True)
        peak = max(peak, f.speed)
    assert 1.8 < peak < 2.2


def test_do_jump_repeats_the_items_its_count_says() -> None:
    f = Flight([TAKEOFF_ITEM, wp(6, 0), wp(6, 6), do(DO_JUMP, 1, 1), wp(0, 6)])
    f.start()
    f.run_until(lambda: f.store.finished, 120.0)
    assert f.currents == [0, 1, 2, 1, 2, 4]


def test_roi_location_turns_the_vehicle_towards_it_until_roi_none() -> None:
    f = Flight([TAKEOFF_ITEM, wp(0, -40, 5.0, cmd=ROI_LOCATION), wp(30, 0), do(ROI_NONE), wp(30, 30)])
    f.start()
    f.run_until(lambda: f.store.current_seq == 2)
    f.v.run_for(4.0)
    p, yaw = f.v.snapshot().pos_ned_m, f.v.snapshot().euler_rad[2]
    assert abs(math.remainder(yaw - math.atan2(-40 - p[1], -p[0]), math.tau)) < 0.15
    f.run_until(lambda: f.store.current_seq == 4)
    f.v.run_for(6.0)  # a turn of ~140 deg: ~5.4 s at MPC_YAWRAUTO_ACC 20 deg/s^2 (HeadingSmoothing)
    assert abs(math.remainder(f.v.snapshot().euler_rad[2] - math.pi / 2, math.tau)) < 0.15  # faces the waypoint


def test_amsl_altitude_frame() -> None:
    f = Flight([TAKEOFF_ITEM, wp(10, 0, 489.4 + 9.0, frame=AMSL)])
    f.start()
    f.run_until(lambda: f.store.finished)
    f.v.run_for(5.0)
    assert -f.v.snapshot().pos_ned_m[2] == pytest.approx(9.0, abs=0.5)


def test_auto_mission_needs_a_mission() -> None:
    """Without a mission MISSION_START is denied; AUTO.MISSION can be chosen while disarmed (as any mode), but
    arming in it fails the mode check (modeCheck.cpp)."""
    f = Flight([])
    f.v.run_for(2.5)
    assert f.command(MavCmd.MISSION_START, 0, 0) == MavResult.DENIED
    assert f.command(MavCmd.DO_SET_MODE, 1, 4, 4) == MavResult.ACCEPTED
    assert f.v.commander.nav_state is NavState.AUTO_MISSION
    assert f.command(MavCmd.COMPONENT_ARM_DISARM, 1, 0) == MavResult.TEMPORARILY_REJECTED
    f.run_until(lambda: True)
    assert f.texts[-3:] == ["Mission start denied! No valid mission", "Preflight Fail: No valid mission available",
                            "Arming denied: Resolve system health failures first"]


def _state(f: Flight) -> int:
    """MISSION_CURRENT.mission_state now (mission_items.mission_current_fields)."""
    return f.store.mission_state(f.v.snapshot().nav_state is NavState.AUTO_MISSION)


def test_a_finished_mission_started_again_is_active_from_its_first_report() -> None:
    """MISSION_CURRENT.mission_state: ACTIVE while a mission runs, COMPLETE only after its last item (px4-mission
    cases.json flight1.sequence: 3, 3, 3, 3, 5); a finished mission started again is not reported COMPLETE."""
    f = Flight([TAKEOFF_ITEM, wp(10, 0), do(MavCmd.NAV_RETURN_TO_LAUNCH)])
    f.start()
    assert _state(f) == MISSION_STATE_ACTIVE
    f.run_until(lambda: f.store.finished)
    assert _state(f) == MISSION_STATE_COMPLETE
    f.run_until(lambda: not f.v.snapshot().armed, 90.0)
    f.v.run_for(1.0)
    assert f.command(MavCmd.COMPONENT_ARM_DISARM, 1, 0) == MavResult.ACCEPTED
    assert f.command(MavCmd.MISSION_START, 0, 0) == MavResult.ACCEPTED
    for _ in range(50):
        assert _state(f) == MISSION_STATE_ACTIVE
        f.v.step()


@pytest.mark.parametrize(("reset", "currents"), [(0, [1, 2, 4]), (1, [1, 2, 1, 2, 4])])
def test_set_mission_current_param2_resets_the_jump_counters(reset: int, currents: list[int]) -> None:
    """navigator_main.cpp DO_SET_MISSION_CURRENT: param2 1 resets every DO_JUMP's repeat count
    (Mission::set_current_mission_index), so a jump already used repeats again; 0 keeps the counts."""
    f = Flight([TAKEOFF_ITEM, wp(6, 0), wp(6, 6), do(DO_JUMP, 1, 1), wp(0, 6), wp(0, 12)])
    f.start()
    f.run_until(lambda: f.store.current_seq == 4, 120.0)
    assert f.currents == [0, 1, 2, 1, 2, 4]
    f.currents.clear()
    assert f.command(MavCmd.DO_SET_MISSION_CURRENT, 1, reset) == MavResult.ACCEPTED
    f.run_until(lambda: f.store.current_seq == 5, 120.0)
    flown = [seq for seq in f.currents if seq != 5]
    assert (flown[1:] if flown[0] == 4 else flown) == currents  # from the item set, until item 5 is current


def test_the_heading_setpoint_and_its_rate_carry_over_into_hold() -> None:
    """FlightModeManager::switchTask keeps FlightTaskAuto running when Hold follows Mission (the same task): the
    heading setpoint turns on at the rate it had and slows down from there, rather than restarting at rest."""
    f = Flight([TAKEOFF_ITEM, wp(20, 0), wp(20, -20), wp(0, -20)])
    f.start()

    def yawspeed() -> float:
        sp = f.v.snapshot().local_setpoint
        return sp.yawspeed_rad_s if sp is not None else 0.0

    f.run_until(lambda: f.store.current_seq == 2 and abs(yawspeed()) > 0.3, 60.0)
    before = yawspeed()
    assert f.command(MavCmd.DO_SET_MODE, 1, 4, 3) == MavResult.ACCEPTED  # AUTO.LOITER
    f.v.step()
    f.v.step()
    assert f.v.snapshot().nav_state is NavState.AUTO_LOITER
    assert abs(yawspeed() - before) < 0.1


@pytest.mark.parametrize("yaw_mode", [0, 4])
def test_yaw_mode_4_turns_to_the_waypoint_before_it_moves(yaw_mode: int) -> None:
    """MPC_YAW_MODE 4 (towards the waypoint, yaw first): FlightTaskAuto forces a zero velocity setpoint while the
    heading setpoint is not aligned (within MIS_YAW_ERR, not turning at the rate limit); 0 turns while it flies."""
    f = Flight([TAKEOFF_ITEM, wp(0, 30), wp(0, 0)])
    f.v.params.set("MPC_YAW_MODE", yaw_mode)
    f.start()
    f.run_until(lambda: f.store.current_seq == 1, 60.0)
    moved_while_turning = 0.0
    while f.v.snapshot().euler_rad[2] < math.radians(60.0):  # turning from north to east
        f.v.step()
        moved_while_turning = max(moved_while_turning, abs(f.v.snapshot().pos_ned_m[1]))
        assert f.v.time_us < 60e6
    assert (moved_while_turning < 0.2) if yaw_mode == 4 else (moved_while_turning > 0.5)
    f.run_until(lambda: f.store.seq_reached == 1, 60.0)  # and it does get there
