"""The one tick loop (sitl_emu/runtime/timeline.py) that the runners and Sim share."""

from __future__ import annotations

from sitl_emu.runtime.timeline import Timeline


class FakeVehicle:
    dt_us = 4000

    def __init__(self, log: list[str], name: str, reboot_at_us: int | None = None) -> None:
        self.time_us = 0
        self.log, self.name, self.reboot_at_us = log, name, reboot_at_us

    def step(self) -> None:
        self.log.append(f"step {self.name}")
        self.time_us += self.dt_us
        if self.time_us == self.reboot_at_us:
            self.time_us = 0
            self.reboot_at_us = None


class FakeNode:
    def __init__(self, vehicle: FakeVehicle) -> None:
        self.vehicle = vehicle
        self.readable: list[int] = []

    def step_io(self, now_us: int, readable: int) -> None:
        self.vehicle.log.append(f"io {self.vehicle.name}")
        self.readable.append(readable)


def test_every_vehicle_ticks_before_any_ticks_again_and_io_follows_the_tick() -> None:
    log: list[str] = []
    nodes = [FakeNode(FakeVehicle(log, "a")), FakeNode(FakeVehicle(log, "b"))]
    timeline = Timeline(nodes)
    assert timeline.advance_to(8000, look=lambda: {1: 2})
    assert log == ["step a", "step b", "io a", "io b"] * 2
    assert nodes[0].readable == [0, 0] and nodes[1].readable == [2, 2]
    assert timeline.time_us == 8000 and timeline.steps == 4


def test_a_rebooted_vehicle_keeps_its_place_and_the_timeline_never_goes_back() -> None:
    log: list[str] = []
    rebooting, steady = FakeVehicle(log, "a", reboot_at_us=8000), FakeVehicle(log, "b")
    timeline = Timeline([FakeNode(rebooting), FakeNode(steady)])
    timeline.advance_to(20_000, look=dict)
    assert timeline.time_us == 20_000
    assert steady.time_us == 20_000
    assert rebooting.time_us == 12_000  # rebooted at 8 ms, then ticked three more times with the others
    assert log.count("step a") == log.count("step b") == 5


def test_no_tick_due_runs_nothing_and_answer_serves_datagrams_between_ticks() -> None:
    log: list[str] = []
    node = FakeNode(FakeVehicle(log, "a"))
    timeline = Timeline([node], start_us=1000)
    assert not timeline.advance_to(4999, look=dict)
    assert log == []
    timeline.answer({0: 1})
    assert log == ["io a"] and node.readable == [1]
