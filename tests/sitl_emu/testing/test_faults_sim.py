"""Wind and faults over loopback UDP with a lockstep Sim: what a client's MAVLink sees (issue 16)."""

from __future__ import annotations

import math
from typing import Any

import pytest

from sitl_emu.control.qmath import euler_from_q
from sitl_emu.disturbance.wind import WindSettings
from sitl_emu.px4 import MavCmd, MavResult, NavState
from sitl_emu.testing.client import FlightClient
from sitl_emu.testing.sim import Sim

GPS, MOTOR = 4, 101
OFF = 1
MAV_TYPE_GCS = 6


class GcsClient(FlightClient):
    """A client that says it is a ground station (the vehicle sends STATUSTEXT only while one is heard)."""

    _next_gcs_s = -math.inf

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.watch("GPS_RAW_INT", "BATTERY_STATUS")
        self.last: dict[str, Any] = {}  # the last message of each type decoded

    def _observe(self, msg: Any) -> None:
        self.last[msg.get_type()] = msg
        super()._observe(msg)

    def pump(self) -> None:
        if self.clock.now() >= self._next_gcs_s:
            self.send(self.mav.heartbeat_encode(MAV_TYPE_GCS, 8, 0, 0, 4))
            self._next_gcs_s = self.clock.now() + 1.0
        super().pump()


def _airborne(sim: Sim, client: FlightClient) -> None:
    client.wait(lambda: client.healthy, 10.0, "healthy")
    assert client.command(MavCmd.NAV_TAKEOFF) == MavResult.ACCEPTED
    assert client.command(MavCmd.COMPONENT_ARM_DISARM, 1) == MavResult.ACCEPTED
    client.wait(lambda: client.in_mode(NavState.AUTO_TAKEOFF), 2.0, "Takeoff")
    client.wait(lambda: client.in_mode(NavState.AUTO_LOITER), 20.0, "Hold after the takeoff")


def test_hover_in_a_5_m_s_wind_holds_position_and_tilts_into_it():
    with Sim(wind=WindSettings(5.0, 270.0)) as sim:
        client = GcsClient(sim.ports(0).api, sim.clock)
        _airborne(sim, client)
        client.spin(15.0)
        n, e, d = client.seen.pos_ned_m or (math.nan,) * 3
        assert math.hypot(n, e) < 0.5 and d == pytest.approx(-2.5, abs=0.3)  # LOCAL_POSITION_NED
        roll = euler_from_q(sim.vehicle(0).snapshot().q_wxyz)[0]
        assert roll < math.radians(-20)  # leaning west, into the wind from the west
        client.close()


def test_inject_failure_denied_over_mavlink_without_sys_failure_en():
    with Sim(params={"SYS_FAILURE_EN": 0}) as sim:
        client = GcsClient(sim.ports(0).api, sim.clock)
        assert client.command(MavCmd.INJECT_FAILURE, GPS, OFF, 0) == MavResult.DENIED
        client.spin(0.5)
        assert not [t for t in client.seen.texts if "Injected" in t]
        client.close()


def test_gps_off_over_mavlink_acks_tells_and_descends():
    with Sim() as sim:
        client = GcsClient(sim.ports(0).api, sim.clock)
        _airborne(sim, client)
        assert client.command(MavCmd.INJECT_FAILURE, GPS, OFF, 0) == MavResult.ACCEPTED
        client.wait(lambda: client.in_mode(NavState.DESCEND), 7.0, "Descend")
        assert "Injected: gps off, all instances" in client.seen.texts
        assert "Failsafe activated\t" in client.seen.texts
        assert client.last["GPS_RAW_INT"].fix_type == 0 and client.last["GPS_RAW_INT"].satellites_visible == 0
        assert not client.seen.sys_status.onboard_control_sensors_health & 0x20  # SYS_STATUS: GPS unhealthy
        client.wait(lambda: not client.armed, 20.0, "landed and disarmed")
        client.close()


def test_motor_off_over_mavlink_the_vehicle_falls():
    with Sim() as sim:
        client = GcsClient(sim.ports(0).api, sim.clock)
        _airborne(sim, client)
        assert client.command(MavCmd.INJECT_FAILURE, MOTOR, OFF, 3) == MavResult.ACCEPTED
        client.spin(2.0)
        assert client.seen.pos_ned_m is not None and client.seen.pos_ned_m[2] > -0.2  # down on the ground
        assert "Injected: motor off, instances 3" in client.seen.texts
        client.close()


@pytest.mark.slow
def test_battery_drain_ends_in_return_with_px4_texts():
    with Sim(params={"SIM_BAT_DRAIN": 40.0, "SIM_BAT_MIN_PCT": 6.0}) as sim:
        client = GcsClient(sim.ports(0).api, sim.clock)
        _airborne(sim, client)
        client.wait(lambda: client.in_mode(NavState.AUTO_RTL), 45.0, "Return")
        texts = client.seen.texts
        low, crit = texts.index("Low battery\t"), texts.index("Critical battery\t")
        assert low < crit < texts.index("Failsafe activated: entering Hold for 5 seconds\t")
        assert client.seen.sys_status.battery_remaining in (6, 7)
        client.spin(2.5)  # BATTERY_STATUS at 0.5 Hz
        assert client.last["BATTERY_STATUS"].charge_state == 3  # MAV_BATTERY_CHARGE_STATE_CRITICAL
        client.close()


def test_gcs_heartbeats_stopping_trigger_nav_dll_act():
    with Sim(params={"NAV_DLL_ACT": 2}) as sim:
        gcs = FlightClient(sim.ports(0).gcs, sim.clock, sysid=255, compid=190)
        client = FlightClient(sim.ports(0).api, sim.clock, sysid=254)
        for _ in range(3):
            gcs.send(gcs.mav.heartbeat_encode(MAV_TYPE_GCS, 8, 0, 0, 4))
            client.spin(0.5)
        _airborne(sim, client)  # > COM_DL_LOSS_T later: the link is lost by now
        client.wait(lambda: client.in_mode(NavState.AUTO_RTL), 10.0, "Return")
        texts = [e.text for e in sim.vehicle(0).events_after(0)]  # no GCS, no STATUSTEXT: the vehicle's log
        lost = texts.index("Connection to ground station lost")
        assert texts[lost + 1:lost + 3] == ["Failsafe activated: entering Hold for 5 seconds", "Failsafe activated"]
        gcs.close()
        client.close()


def test_estimate_noise_reaches_local_position_ned_and_is_seeded():
    from sitl_emu.disturbance.estimate import EstimateNoiseSettings

    def fly(seed: int) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
        with Sim(seed=seed, estimate_noise=EstimateNoiseSettings(pos_white_m=0.2)) as sim:
            client = GcsClient(sim.ports(0).api, sim.clock)
            _airborne(sim, client)
            client.spin(1.0)
            seen = client.seen.pos_ned_m
            client.close()
            assert seen is not None
            return seen, sim.vehicle(0)._state.pos_ned_m

    seen, truth = fly(1)
    assert seen != pytest.approx(truth, abs=1e-3) and math.dist(seen, truth) < 1.5  # an estimate, not the truth
    assert fly(1)[0] == seen and fly(2)[0] != seen
