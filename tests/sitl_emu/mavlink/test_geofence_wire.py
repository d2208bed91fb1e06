"""The geofence and rally points on the wire, over loopback UDP in lockstep simulated time: a ground station (GCS
HEARTBEAT, so PX4's STATUSTEXTs reach it) uploads a fence or rally plan with the mission protocol, flies the vehicle
out with DO_REPOSITION or a takeoff, and sees the breach handled as GF_ACTION says (PX4 main: navigator
geofence_breach_check, commander geofenceCheck.cpp and failsafe.cpp), or RTL land at the rally point RTL_TYPE picks.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Any

import pytest
from support.events_client import EVENT, EventsDecoder, extra_of

from sitl_emu.events.metadata import events_metadata
from sitl_emu.geo import GeoRef, ned_to_global
from sitl_emu.px4 import MavCmd, MavResult, MavState, NavState
from sitl_emu.testing.client import FlightClient
from sitl_emu.testing.sim import Sim

NAN = math.nan
MAV_STATE_CRITICAL = 5
S_PREARM_CHECK = 0x10000000
POLY_IN, CIRCLE_IN, RALLY = 5001, 5003, 5100
FENCE, RALLY_PLAN = 1, 2


class Gcs(FlightClient):
    """A ground station: GCS HEARTBEATs (PX4 sends STATUSTEXT only to links with a GCS), and the mission answers."""

    def __init__(self, sim: Sim) -> None:
        super().__init__(sim.ports(0).api, sim.clock, sysid=245, compid=190)
        self.mission: list[Any] = []
        self.events: list[dict[str, Any]] = []  # EVENT's fields, once watch_all() decodes them
        self._next_gcs_hb_s = -math.inf

    def pump(self) -> None:
        self._next_heartbeat_s = math.inf  # no onboard-controller HEARTBEAT: we are a GCS
        super().pump()
        now = self.clock.now()
        if now >= self._next_gcs_hb_s:
            self.send(self.mav.heartbeat_encode(6, 8, 0, 0, 4))
            self._next_gcs_hb_s = now + 1.0

    def _observe(self, msg: Any) -> None:
        super()._observe(msg)
        if msg.get_type() in ("MISSION_REQUEST_INT", "MISSION_REQUEST", "MISSION_ACK", "MISSION_COUNT"):
            self.mission.append(msg)
        extra = extra_of(msg)
        if extra is not None and extra[0] == EVENT:
            self.events.append(extra[1])

    def upload(self, items: list[Any], mission_type: int) -> int:
        """MISSION_COUNT, then each requested item; the MISSION_ACK type."""
        self.mission.clear()
        self.send(self.mav.mission_count_encode(1, 1, len(items), mission_type))
        done = 0
        while True:
            self.wait(lambda n=done: len(self.mission) > n, 2.0, "a mission answer")
            msg = self.mission[done]
            done += 1
            if msg.get_type() == "MISSION_ACK":
                return int(msg.type)
            self.send(items[msg.seq])

    def texts_after(self, n: int) -> list[str]:
        """The geofence, failsafe and RTL texts since the n-th text (PX4's event tab removed)."""
        kinds = ("Geofence", "Failsafe", "RTL", "Arming", "Reposition")
        return [t.rstrip("\t") for t in self.seen.texts[n:] if t.startswith(kinds)]


@pytest.fixture()
def sim() -> Iterator[Sim]:
    with Sim() as s:
        yield s


def _ref(sim: Sim) -> GeoRef:
    return sim.vehicle().ref


def fence_item(gcs: Gcs, sim: Sim, seq: int, command: int, north: float, east: float, p1: float,
               mission_type: int = FENCE, z: float = 0.0) -> Any:
    lat, lon, _ = ned_to_global(_ref(sim), (north, east, 0.0))
    return gcs.mav.mission_item_int_encode(1, 1, seq, 6, command, 0, 1, p1, 0, 0, 0, round(lat * 1e7),
                                           round(lon * 1e7), z, mission_type)


def circle(gcs: Gcs, sim: Sim, radius: float) -> list[Any]:
    return [fence_item(gcs, sim, 0, CIRCLE_IN, 0.0, 0.0, radius)]


def fly_up(sim: Sim, gcs: Gcs, params: dict[str, float]) -> None:
    """Healthy, parameters set, armed, taken off to MIS_TAKEOFF_ALT (2.5 m) and holding."""
    gcs.wait(lambda: gcs.healthy, 10.0, "healthy")
    for name, value in params.items():
        sim.vehicle().params.set(name, value)
    assert gcs.command(MavCmd.COMPONENT_ARM_DISARM, 1) == MavResult.ACCEPTED
    assert gcs.command(MavCmd.NAV_TAKEOFF) == MavResult.ACCEPTED
    gcs.wait(lambda: gcs.in_mode(NavState.AUTO_TAKEOFF), 5.0, "Takeoff")
    gcs.wait(lambda: gcs.in_mode(NavState.AUTO_LOITER), 15.0, "Hold after the takeoff")
    gcs.spin(1.0)


def reposition(sim: Sim, gcs: Gcs, north: float, east: float, up: float) -> None:
    lat, lon, alt = ned_to_global(_ref(sim), (north, east, -up))
    assert gcs.command(MavCmd.DO_REPOSITION, -1, 1, 0, NAN, lat, lon, alt) == MavResult.ACCEPTED


def offboard_to(gcs: Gcs, north_m: float, east_m: float, up_m: float) -> None:
    """OFFBOARD (setpoints streamed first, PX4's rule), then a position setpoint: the way out of a fence that
    DO_REPOSITION cannot take (the navigator refuses targets outside it)."""
    assert gcs.seen.pos_ned_m is not None
    gcs.setpoint_ned_m = gcs.seen.pos_ned_m
    gcs.spin(1.0)
    assert gcs.set_mode(NavState.OFFBOARD) == MavResult.ACCEPTED
    gcs.wait(lambda: gcs.in_mode(NavState.OFFBOARD), 2.0, "OFFBOARD")
    gcs.setpoint_ned_m = (north_m, east_m, -up_m)


def north(gcs: Gcs) -> float:
    assert gcs.seen.pos_ned_m is not None
    return gcs.seen.pos_ned_m[0]


@pytest.mark.slow
def test_fence_upload_and_breach_with_hold(sim):
    """GF_ACTION 2 (the default): the breach is reported, the failsafe holds at the breach point, arming checks fail
    (SYS_STATUS PRE_ARM unhealthy); the user's mode change (Return) takes over and is flown."""
    gcs = Gcs(sim)
    half = 30.0
    square = [(-half, -half), (-half, half), (half, half), (half, -half)]
    fence = [fence_item(gcs, sim, i, POLY_IN, n, e, 4) for i, (n, e) in enumerate(square)]
    gcs.wait(lambda: gcs.healthy, 10.0, "healthy")
    assert gcs.upload(fence, FENCE) == 0
    fly_up(sim, gcs, {})
    n0 = len(gcs.seen.texts)
    offboard_to(gcs, 70.0, 0.0, 5.0)
    gcs.wait(lambda: gcs.in_mode(NavState.AUTO_LOITER), 30.0, "the Hold failsafe")
    assert gcs.seen.heartbeat.system_status == MAV_STATE_CRITICAL
    assert gcs.texts_after(n0) == ["Geofence: approaching or outside geofence", "Failsafe activated"]
    assert 25.0 < north(gcs) < 40.0
    breach_north = north(gcs)
    gcs.wait(lambda: north(gcs) > breach_north + 10.0, 10.0, "the overshoot (braking from ~10 m/s)")
    gcs.wait(lambda: abs(north(gcs) - breach_north) < 1.5, 40.0, "Hold back at the breach point")
    assert gcs.in_mode(NavState.AUTO_LOITER)
    assert not gcs.seen.sys_status.onboard_control_sensors_health & S_PREARM_CHECK
    assert gcs.command(MavCmd.NAV_RETURN_TO_LAUNCH) == MavResult.ACCEPTED
    gcs.wait(lambda: not gcs.armed, 60.0, "landed at home")
    assert abs(north(gcs)) < 1.0
    assert "Failsafe activated" not in gcs.texts_after(n0)[2:]  # the takeover does not trigger it again


@pytest.mark.parametrize(("action", "mode"), [(3, NavState.AUTO_RTL), (5, NavState.AUTO_LAND)])
@pytest.mark.slow
def test_fence_breach_return_or_land_after_the_hold(sim, action, mode):
    gcs = Gcs(sim)
    gcs.wait(lambda: gcs.healthy, 10.0, "healthy")
    assert gcs.upload(circle(gcs, sim, 25.0), FENCE) == 0
    fly_up(sim, gcs, {"GF_ACTION": action})
    n0 = len(gcs.seen.texts)
    offboard_to(gcs, 60.0, 0.0, 5.0)
    t_hold = gcs.wait(lambda: "Failsafe activated: entering Hold for 5 seconds" in gcs.texts_after(n0), 30.0,
                      "the delayed failsafe")
    t_action = gcs.wait(lambda: gcs.in_mode(mode), 10.0, "the failsafe action")
    assert 4.0 < t_action < 6.0, (t_hold, t_action)
    texts = gcs.texts_after(n0)
    assert texts[:3] == ["Geofence: approaching or outside geofence",
                         "Failsafe activated: entering Hold for 5 seconds", "Failsafe activated"]
    gcs.wait(lambda: not gcs.armed, 90.0, "landed")
    if mode is NavState.AUTO_RTL:
        assert abs(north(gcs)) < 1.0 and any(t.startswith("RTL: start return at") for t in texts)
    else:
        assert north(gcs) > 25.0


@pytest.mark.slow
def test_max_horizontal_distance_breach_lands(sim):
    gcs = Gcs(sim)
    fly_up(sim, gcs, {"GF_MAX_HOR_DIST": 20.0, "GF_ACTION": 5, "COM_FAIL_ACT_T": 0.0})
    n0 = len(gcs.seen.texts)
    offboard_to(gcs, 0.0, 50.0, 5.0)
    gcs.wait(lambda: gcs.in_mode(NavState.AUTO_LAND), 30.0, "Land")
    assert gcs.texts_after(n0)[:2] == ["Geofence: exceeding maximum distance to Home", "Failsafe activated"]
    gcs.wait(lambda: not gcs.armed, 60.0, "landed")
    assert gcs.seen.pos_ned_m is not None and 20.0 < gcs.seen.pos_ned_m[1] < 50.0  # at the braking point


def test_takeoff_above_max_vertical_distance_holds(sim):
    gcs = Gcs(sim)
    gcs.wait(lambda: gcs.healthy, 10.0, "healthy")
    for name, value in {"GF_MAX_VER_DIST": 6.0, "MIS_TAKEOFF_ALT": 15.0}.items():
        sim.vehicle().params.set(name, value)
    n0 = len(gcs.seen.texts)
    assert gcs.command(MavCmd.COMPONENT_ARM_DISARM, 1) == MavResult.ACCEPTED
    assert gcs.command(MavCmd.NAV_TAKEOFF) == MavResult.ACCEPTED
    gcs.wait(lambda: gcs.in_mode(NavState.AUTO_TAKEOFF), 5.0, "Takeoff")
    gcs.wait(lambda: gcs.in_mode(NavState.AUTO_LOITER), 30.0, "the Hold failsafe")
    assert "Geofence: exceeding maximum altitude above Home" in gcs.texts_after(n0)
    gcs.spin(6.0)
    assert gcs.seen.pos_ned_m is not None and 5.5 < -gcs.seen.pos_ned_m[2] < 8.0


def test_arming_is_refused_while_breached(sim):
    gcs = Gcs(sim)
    gcs.wait(lambda: gcs.healthy, 10.0, "healthy")
    sim.vehicle().params.set("GF_MAX_VER_DIST", 6.0)
    sim.vehicle().commander.home_from_global(*ned_to_global(_ref(sim), (0.0, 0.0, 10.0)), 0.0)  # home 10 m below
    gcs.wait(lambda: not gcs.seen.sys_status.onboard_control_sensors_health & S_PREARM_CHECK, 2.0, "PRE_ARM unhealthy")
    n0 = len(gcs.seen.texts)
    assert gcs.command(MavCmd.COMPONENT_ARM_DISARM, 1) == MavResult.TEMPORARILY_REJECTED
    assert gcs.texts_after(n0)[-2:] == ["Geofence: exceeding maximum altitude above Home",
                                        "Arming denied: Resolve system health failures first"[:50]]  # 1st chunk


@pytest.mark.slow
def test_rtl_lands_at_the_closest_rally_point(sim):
    gcs = Gcs(sim)
    gcs.wait(lambda: gcs.healthy, 10.0, "healthy")
    rally = [fence_item(gcs, sim, 0, RALLY, 0.0, 40.0, 0, RALLY_PLAN, z=0.0),
             fence_item(gcs, sim, 1, RALLY, 0.0, -80.0, 0, RALLY_PLAN, z=0.0)]
    assert gcs.upload(rally, RALLY_PLAN) == 0
    fly_up(sim, gcs, {})
    reposition(sim, gcs, 0.0, 60.0, 5.0)
    gcs.wait(lambda: gcs.seen.pos_ned_m is not None and gcs.seen.pos_ned_m[1] > 58.0, 30.0, "out east")
    n0 = len(gcs.seen.texts)
    assert gcs.command(MavCmd.NAV_RETURN_TO_LAUNCH) == MavResult.ACCEPTED
    gcs.wait(lambda: not gcs.armed, 60.0, "landed")
    assert gcs.seen.pos_ned_m is not None and abs(gcs.seen.pos_ned_m[1] - 40.0) < 1.0
    # the destination's altitude is home's (a rally point 0 m above home); STATUSTEXT chunks at 50 characters
    assert "RTL: start return at 520 m (31 m above destination" in gcs.texts_after(n0)  # 519.4f - 489.4f: 30.00003


@pytest.mark.parametrize(("count", "answer"), [(2, 1), (4, 0)])
def test_bad_polygons(sim, count, answer):
    """Fewer than 3 vertices: MAV_MISSION_ERROR (mavlink_mission.cpp). A vertex count larger than the vertices sent
    is accepted, but the polygon cannot be read: it contains nothing, not home, and is discarded with PX4's text."""
    gcs = Gcs(sim)
    gcs.wait(lambda: gcs.healthy, 10.0, "healthy")
    n0 = len(gcs.seen.texts)
    tri = [fence_item(gcs, sim, i, POLY_IN, n, e, count) for i, (n, e) in enumerate([(-20, -20), (-20, 20), (20, 0)])]
    assert gcs.upload(tri[:2] if count == 2 else tri, FENCE) == answer
    gcs.spin(0.5)
    if answer == 0:
        assert gcs.texts_after(n0) == ["Geofence invalid, doesn't contain Home position"]
        assert sim.vehicle().commander.geofence.triggered is False


@pytest.mark.parametrize("with_circle", [True, False])
def test_a_placeholder_circle_at_0_0_is_stored_and_the_fence_refused(sim, with_circle):
    """../shared/reference/px4-recorded-facts.md section 4 (what MAVSDK-Python's geofence example uploads): four
    polygon vertices +-0.0001 deg around home and a circle at x = y = 0 with radius 0. PX4 accepts all five items
    (a fence circle uses x and y, so 0, 0 is a position, not the unused-param check of an RTL item) and then says,
    once, that the fence does not contain home; without the circle the fence is valid."""
    gcs = Gcs(sim)
    gcs.wait(lambda: gcs.healthy, 10.0, "healthy")
    lat, lon = round(_ref(sim).lat_deg * 1e7), round(_ref(sim).lon_deg * 1e7)
    corners = [(lat + 1000, lon + 1000), (lat + 1000, lon - 1000), (lat - 1000, lon - 1000), (lat - 1000, lon + 1000)]
    items = [gcs.mav.mission_item_int_encode(1, 1, i, 6, POLY_IN, 0, 1, 4, 0, 0, 0, x, y, 0.0, FENCE)
             for i, (x, y) in enumerate(corners)]
    if with_circle:
        items.append(gcs.mav.mission_item_int_encode(1, 1, 4, 6, CIRCLE_IN, 0, 1, 0, 0, 0, 0, 0, 0, 0.0, FENCE))
    n0 = len(gcs.seen.texts)
    assert gcs.upload(items, FENCE) == 0  # MAV_MISSION_ACCEPTED
    gcs.spin(1.0)
    invalid = ["Geofence invalid, doesn't contain Home position"] if with_circle else []
    assert gcs.texts_after(n0) == invalid


@pytest.mark.slow
def test_reposition_outside_the_fence_is_refused(sim):
    """navigator_main.cpp: a DO_REPOSITION target outside the fence is not flown ("Reposition is outside geofence");
    commander acknowledges the command all the same. A target inside is flown."""
    gcs = Gcs(sim)
    gcs.wait(lambda: gcs.healthy, 10.0, "healthy")
    assert gcs.upload(circle(gcs, sim, 25.0), FENCE) == 0
    fly_up(sim, gcs, {})
    n0 = len(gcs.seen.texts)
    reposition(sim, gcs, 40.0, 0.0, 5.0)
    gcs.spin(5.0)
    assert gcs.texts_after(n0) == ["Reposition is outside geofence"]
    assert abs(north(gcs)) < 1.0
    reposition(sim, gcs, 15.0, 0.0, 5.0)
    gcs.wait(lambda: abs(north(gcs) - 15.0) < 0.5, 20.0, "the allowed reposition")


def test_warning_only_reports_and_terminate_stops_the_motors(sim):
    """GF_ACTION 1: the breach text and the failsafe warning's EVENT (framework.cpp notifyUser, Action::Warn: no
    "Failsafe activated" STATUSTEXT), no failsafe, the flight goes on; GF_ACTION 4: termination at once (HEARTBEAT
    FLIGHT_TERMINATION, the vehicle falls)."""
    gcs = Gcs(sim)
    gcs.watch_all()  # EVENT is no message of pymavlink's dialect: decoded with the rest (support/events_client.py)
    fly_up(sim, gcs, {"GF_MAX_HOR_DIST": 15.0, "GF_ACTION": 1})
    n0, e0 = len(gcs.seen.texts), len(gcs.events)
    offboard_to(gcs, 0.0, 25.0, 5.0)
    gcs.wait(lambda: gcs.seen.pos_ned_m is not None and abs(gcs.seen.pos_ned_m[1] - 25.0) < 1.0, 30.0, "25 m east")
    assert gcs.texts_after(n0) == ["Geofence: exceeding maximum distance to Home"]
    decoder = EventsDecoder(events_metadata())
    notices = [decoder.decode(e["id"], e["arguments"]) for e in gcs.events[e0:]]
    assert notices.count(("commander_failsafe_enter_generic_warn", "Failsafe warning:")) == 1
    assert gcs.in_mode(NavState.OFFBOARD) and gcs.seen.heartbeat.system_status != MAV_STATE_CRITICAL
    sim.vehicle().params.set("GF_ACTION", 4)
    gcs.wait(lambda: gcs.in_mode(NavState.TERMINATION), 5.0, "termination")
    assert gcs.texts_after(n0)[1:] == ["Failsafe activated"]
    gcs.wait(lambda: gcs.seen.pos_ned_m is not None and gcs.seen.pos_ned_m[2] > -0.5, 10.0, "the fall")
    assert gcs.seen.heartbeat.system_status == MavState.FLIGHT_TERMINATION


def mission_item(gcs: Gcs, sim: Sim, seq: int, north_m: float, east_m: float) -> Any:
    lat, lon, _ = ned_to_global(_ref(sim), (north_m, east_m, 0.0))
    return gcs.mav.mission_item_int_encode(1, 1, seq, 6, 16, 0, 1, 0, 0, 0, NAN, round(lat * 1e7), round(lon * 1e7),
                                           5.0, 0)


def test_a_mission_outside_the_fence_is_not_flown(sim):
    """checkMissionAgainstGeofence (mission_feasibility_checker.cpp): after an upload, a waypoint outside the fence
    is reported once and makes the mission invalid, so MISSION_START is refused; a fence that holds it makes the same
    mission valid again."""
    gcs = Gcs(sim)
    gcs.wait(lambda: gcs.healthy, 10.0, "healthy")
    assert gcs.upload(circle(gcs, sim, 20.0), FENCE) == 0
    n0 = len(gcs.seen.texts)
    assert gcs.upload([mission_item(gcs, sim, 0, 10.0, 0.0), mission_item(gcs, sim, 1, 50.0, 0.0)], 0) == 0
    gcs.wait(lambda: "Geofence violation for waypoint 2" in gcs.texts_after(n0), 2.0, "the mission's fence check")
    assert gcs.command(MavCmd.COMPONENT_ARM_DISARM, 1) == MavResult.ACCEPTED
    assert gcs.command(MavCmd.MISSION_START, 0, 0) != MavResult.ACCEPTED
    assert gcs.command(MavCmd.COMPONENT_ARM_DISARM, 0) == MavResult.ACCEPTED
    assert gcs.upload(circle(gcs, sim, 80.0), FENCE) == 0
    gcs.spin(0.5)
    assert gcs.command(MavCmd.COMPONENT_ARM_DISARM, 1) == MavResult.ACCEPTED
    assert gcs.command(MavCmd.MISSION_START, 0, 0) == MavResult.ACCEPTED
    assert gcs.texts_after(n0).count("Geofence violation for waypoint 2") == 1
