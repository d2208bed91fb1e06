"""The vehicle's plan store (navigator/mission_store.py): whole plans replaced at once, cleared per type, the current
item, the vehicle-wide upload lock, and nothing kept across a reboot (no storage file, unlike PX4's dataman file)."""

from __future__ import annotations

from sitl_emu.navigator.mission_store import (
    MISSION_STATE_NO_MISSION,
    MISSION_STATE_NOT_STARTED,
    PLAN_ALL,
    PLAN_FENCE,
    PLAN_MISSION,
    PLAN_RALLY,
    MissionItem,
    MissionStore,
)
from sitl_emu.vehicle.vehicle import Vehicle


def _wp(seq: int, x: int = 473977420) -> MissionItem:
    return MissionItem(seq, 6, 16, 1, 0.0, 0.0, 0.0, 0.0, x, 85455940, 5.0)


def test_replace_clear_and_current_item() -> None:
    store = MissionStore()
    assert store.mission_state() == MISSION_STATE_NO_MISSION
    plan = store.replace(PLAN_MISSION, (_wp(0), _wp(1)), current_seq=1)
    assert (plan.count, store.current_seq, store.mission_state()) == (2, 1, MISSION_STATE_NOT_STARTED)
    assert plan.opaque_id != 0 and store.replace(PLAN_MISSION, (_wp(0), _wp(1, x=1))).opaque_id != plan.opaque_id
    assert store.current_seq == 0  # no item marked current: the first
    assert not store.set_current(2) and store.set_current(1) and store.current_seq == 1
    store.replace(PLAN_RALLY, (_wp(0),))
    store.clear(PLAN_MISSION)
    assert (store.count(PLAN_MISSION), store.count(PLAN_RALLY), store.plan(PLAN_FENCE).opaque_id) == (0, 1, 0)
    store.clear(PLAN_ALL)
    assert store.count(PLAN_RALLY) == 0


def test_one_upload_at_a_time() -> None:
    store, a, b = MissionStore(), object(), object()
    assert store.try_lock(a) and store.try_lock(a) and not store.try_lock(b)
    store.unlock(b)  # only the owner releases it
    assert not store.try_lock(b)
    store.unlock(a)
    assert store.try_lock(b)


def test_a_reboot_forgets_the_plans() -> None:
    vehicle = Vehicle()
    vehicle.mission_store().replace(PLAN_MISSION, (_wp(0),))
    vehicle.reboot()
    assert vehicle.mission_store().count(PLAN_MISSION) == 0
