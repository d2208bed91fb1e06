"""MANUAL_CONTROL against the reference: the protocol cases of ../shared/reference/px4-manual/cases.json, replayed in
the order the probe ran them on one freshly booted vehicle, over loopback UDP in lockstep simulated time.

The probe (a ground station, sysid 245 / compid 190, HEARTBEAT at 1 Hz) streamed MANUAL_CONTROL at 20 Hz to target 1
on the API link; each case's COMMAND_ACK, STATUSTEXTs (text and severity) and the HEARTBEAT after it are compared.
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import pytest
from support.fakes import Client, Harness

from sitl_emu.px4 import MavCmd
from sitl_emu.vehicle.vehicle import Vehicle

# one vehicle flies the cases in order (the module's `pilot`), the last in the air: the module is one slow flight
pytestmark = pytest.mark.slow

# a copy of ../shared/reference/px4-manual (recorded from real PX4 SITL; see its README)
CASES: dict[str, Any] = json.loads((Path(__file__).parents[2] / "reference" / "px4-manual" / "cases.json").read_text())
MODES = {"POSCTL": (3, 0), "ALTCTL": (2, 0), "STABILIZED": (7, 0), "OFFBOARD": (6, 0)}
CENTRE = {"x": 0, "y": 0, "z": 500, "r": 0}
IGNORED_TEXTS = ("[logger]",)  # PX4's log-file announcement; sitl-emu writes no log (yet)


class Pilot:
    """The probe: a GCS on the API link with a 1 Hz HEARTBEAT and, while `sticks` is set, MANUAL_CONTROL at 20 Hz."""

    def __init__(self) -> None:
        self.h = Harness(Vehicle())
        self.h.api = self.client = Client(sysid=245, compid=190)
        self.client.target = ("127.0.0.1", self.h.node.api.link.port)
        self.h.node.api.link.remote = ("127.0.0.1", self.client.port)
        self.sticks: dict[str, int] | None = None
        self._next_hb_us = self._next_stick_us = 0

    def _tick(self) -> None:
        now = self.h.vehicle.time_us
        if now >= self._next_hb_us:
            self.client.heartbeat()
            self._next_hb_us = now + 1_000_000
        if self.sticks is not None and now >= self._next_stick_us:
            s = {**CENTRE, **self.sticks}
            self.client.send(self.client.mav.manual_control_encode(1, s["x"], s["y"], s["z"], s["r"], 0))
            self._next_stick_us = now + 50_000

    def run(self, seconds: float) -> None:
        self.h.run(seconds, self._tick)

    def command(self, command: int, *params: float) -> None:
        self.client.command_long(command, *params)

    def mode(self, name: str) -> None:
        self.command(MavCmd.DO_SET_MODE, 1, *MODES[name])

    def observe(self, action: Any, window_s: float = 1.5) -> dict[str, Any]:
        """Do `action`, run `window_s`, and return what followed: ACK, texts, severities, the last HEARTBEAT."""
        c = self.client
        n_ack, n_txt = len(c.of_type("COMMAND_ACK")), len(c.of_type("STATUSTEXT"))
        action()
        self.run(window_s)
        texts = [t for t in _joined(c.of_type("STATUSTEXT")[n_txt:]) if not t[0].startswith(IGNORED_TEXTS)]
        acks = c.of_type("COMMAND_ACK")[n_ack:]
        hb = c.of_type("HEARTBEAT")[-1]
        return {"ack": acks[0].result if acks else None, "statustext": [t for t, _ in texts],
                "statustext_severity": [sev for _, sev in texts],
                "heartbeat": {"custom_mode": hb.custom_mode, "base_mode": hb.base_mode,
                              "system_status": hb.system_status}}


def _joined(messages: list[Any]) -> list[tuple[str, int]]:
    """STATUSTEXTs longer than 50 characters come in chunks with one id: the whole texts, with their severity."""
    texts: list[tuple[str, int]] = []
    last_id = None
    for m in messages:
        if m.id == last_id and m.chunk_seq > 0:
            texts[-1] = (texts[-1][0] + m.text, m.severity)
        else:
            texts.append((m.text, m.severity))
        last_id = m.id
    return texts


def check(name: str, got: dict[str, Any]) -> None:
    want = CASES[name]
    for key in ("ack", "statustext", "statustext_severity", "heartbeat"):
        if key in want:
            assert got[key] == want[key], f"{name}: {key} {got[key]!r} != PX4's {want[key]!r}"


@pytest.fixture(scope="module")
def pilot():
    p = Pilot()
    p.run(2.5)  # the estimator's warm-up
    yield p
    p.h.close()


def test_mode_changes_before_any_manual_control(pilot):
    for name in ("POSCTL", "ALTCTL", "STABILIZED"):
        check(f"mode_no_manual.{name}", pilot.observe(lambda n=name: pilot.mode(n)))


def test_arming_in_position_mode_without_manual_control(pilot):
    pilot.mode("POSCTL")
    pilot.run(0.2)
    check("arm.posctl_no_manual", pilot.observe(lambda: pilot.command(MavCmd.COMPONENT_ARM_DISARM, 1)))


def test_the_stream_starting_makes_the_manual_modes_ready(pilot):
    pilot.mode("STABILIZED")
    pilot.run(0.2)
    pilot.sticks = dict(CENTRE)
    check("manual.stream_start", pilot.observe(lambda: None))
    for name in ("POSCTL", "ALTCTL", "STABILIZED", "POSCTL2"):
        check(f"mode_with_manual.{name}", pilot.observe(lambda n=name: pilot.mode(n.rstrip("2"))))


def _rc_bits(pilot: Pilot) -> tuple[bool, bool, bool]:
    """SYS_STATUS's RC receiver bit (0x10000): (present, enabled, healthy)."""
    m = pilot.client.of_type("SYS_STATUS")[-1]
    rc = 0x10000
    return (bool(m.onboard_control_sensors_present & rc), bool(m.onboard_control_sensors_enabled & rc),
            bool(m.onboard_control_sensors_health & rc))


def test_losing_and_regaining_the_stream_while_disarmed(pilot):
    assert _rc_bits(pilot) == (True, True, True)  # the joystick is the RC (rcAndDataLinkCheck.cpp)
    pilot.sticks = None
    check("loss_disarmed", pilot.observe(lambda: None, window_s=3.0))
    assert _rc_bits(pilot) == (False, True, False)  # "No manual control input": required, missing
    pilot.sticks = dict(CENTRE)
    check("resume_disarmed", pilot.observe(lambda: None))
    assert _rc_bits(pilot) == (True, True, True)


def test_arming_needs_the_throttle_low_only_where_it_is_the_thrust(pilot):
    pilot.mode("STABILIZED")
    pilot.run(0.2)
    check("arm.stabilized_throttle_centre", pilot.observe(lambda: pilot.command(MavCmd.COMPONENT_ARM_DISARM, 1)))
    pilot.mode("POSCTL")
    pilot.run(0.2)
    check("arm.posctl_throttle_centre", pilot.observe(lambda: pilot.command(MavCmd.COMPONENT_ARM_DISARM, 1)))
    check("disarm.after_centre", pilot.observe(lambda: pilot.command(MavCmd.COMPONENT_ARM_DISARM, 0)))


def test_the_stick_gestures_arm_and_disarm(pilot):
    got = pilot.observe(lambda: pilot.sticks.update(z=0, r=1000), window_s=2.5)
    check("arm.gesture", got)
    pilot.sticks = {"z": 0}
    pilot.run(0.5)
    check("disarm.gesture", pilot.observe(lambda: pilot.sticks.update(r=-1000), window_s=2.5))
    pilot.sticks = {"z": 0}
    pilot.run(0.5)
    check("arm.posctl_throttle_low", pilot.observe(lambda: pilot.command(MavCmd.COMPONENT_ARM_DISARM, 1)))


def _numbers_as_hash(texts: list[str]) -> list[str]:
    return [re.sub(r"\d+", "#", t) for t in texts]


def test_modes_in_the_air_offboard_and_the_stick_loss_failsafe(pilot):
    assert pilot.h.vehicle.snapshot().armed  # armed in Position mode by the previous case
    pilot.sticks = {"z": 1000}
    pilot.run(14.0)  # the throttle takes off and climbs to about 30 m, where the probe's vehicle was
    pilot.sticks = {"x": 1000}  # and flies forward, as the probe's p_fwd trace did: about 23 m from home
    pilot.run(4.0)
    pilot.sticks = dict(CENTRE)
    pilot.run(8.0)
    assert -pilot.h.vehicle.snapshot().pos_ned_m[2] > 25.0
    check("mode_in_air.ALTCTL", pilot.observe(lambda: pilot.mode("ALTCTL")))
    check("mode_in_air.POSCTL", pilot.observe(lambda: pilot.mode("POSCTL")))
    target = pilot.h.vehicle.snapshot().pos_ned_m
    setpoints = pilot.h.vehicle  # offboard setpoints go with every pilot tick from here on
    tick = pilot._tick

    def with_setpoints() -> None:
        tick()
        if setpoints.time_us % 50_000 == 0:
            c = pilot.client
            c.send(c.mav.set_position_target_local_ned_encode(0, 1, 1, 1, 2552, *target, 0, 0, 0, 0, 0, 0, 0, 0))

    pilot._tick = with_setpoints  # type: ignore[method-assign]
    pilot.run(1.0)
    check("offboard.set_mode", pilot.observe(lambda: pilot.mode("OFFBOARD")))
    pilot.sticks = None  # the sticks stop, the setpoints go on (COM_RCL_EXCEPT 0: the loss counts in OFFBOARD)
    got = pilot.observe(lambda: None, window_s=7.0)
    want = CASES["offboard.stick_loss"]
    assert _numbers_as_hash(got["statustext"]) == _numbers_as_hash(want["statustext"]), got["statustext"]
    assert got["statustext_severity"] == want["statustext_severity"]
    assert got["heartbeat"] == want["heartbeat"]
    pilot.sticks = dict(CENTRE)
    check("offboard.stick_resume", pilot.observe(lambda: None, window_s=2.0))  # still returning: sticks centred
    check("offboard.back_to_posctl", pilot.observe(lambda: pilot.mode("POSCTL")))
    pilot._tick = tick  # type: ignore[method-assign]
    pilot.sticks = None
    pilot.run(7.0)  # lost again in Position mode: Hold, then Return
    pilot.sticks = dict(CENTRE)
    pilot.run(1.0)
    check("rc_resume.set_posctl", pilot.observe(lambda: pilot.mode("POSCTL")))
    check("land.nav_land", pilot.observe(lambda: pilot.command(MavCmd.NAV_LAND)))
