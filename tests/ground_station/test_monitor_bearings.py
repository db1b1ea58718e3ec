"""Monitoring actions of one worker take distinct bearings on the ring, so
two of them never send UAVs to one point."""

from __future__ import annotations

import math

import msgspec
import pytest

from ground_station.monitor_bearings import CLEAR_M, choose_bearing, slot_bearings
from proto import (
    AgentState,
    AgentStatus,
    FlightState,
    ModifyAction,
    MonitorAction,
    MonitorTask,
    SubmitAction,
)
from proto.errors import RequestError
from proto.geo import Point
from tests.ground_station.harness import ALL


def watch(k: int = 1, bearing: float | None = None, worker: str = "W2") -> MonitorAction:
    return MonitorAction(
        worker_id=worker, uavs=k, standoff_m=4, duration_s=120, bearing_deg=bearing
    )


@pytest.mark.parametrize(
    ("others", "k", "expected"),
    [
        ([], 1, 0.0),
        ([watch(1, 0.0)], 1, 180.0),
        ([watch(2, 0.0)], 1, 90.0),
        ([watch(3, 0.0)], 3, 60.0),
        ([watch(1, 0.0), watch(1, 180.0)], 2, 90.0),
        ([watch(1, 30.0)], 2, 120.0),
    ],
)
def test_the_bearing_chosen_is_farthest_from_the_other_slots(others, k, expected):
    taken = [b for other in others for b in slot_bearings(other)]
    assert choose_bearing(watch(k), taken) == expected


NEIGHBOURS = {"W2": Point(x_m=0, y_m=0, z_m=0), "W1": Point(x_m=-6, y_m=0, z_m=0)}


@pytest.mark.parametrize(
    ("taken", "k", "expected"),
    [
        ([], 1, 0.0),  # east of W2: 10 m from W1
        ([0.0], 1, 120.0),  # 180 (farthest from the other slot) is 2 m from W1
        ([0.0, 180.0], 1, 90.0),  # taken slots may stand anywhere: only new ones are placed
        ([], 2, 60.0),  # 0 would put slot 1 (180) 2 m from W1; 60 + 180 is the first clear
    ],
)
def test_a_slot_is_kept_nearer_its_own_worker_than_any_other(taken, k, expected):
    """A UAV hovering nearer another worker watches that one (the
    simulator credits it so): the bearing chosen keeps every slot at least
    ``CLEAR_M`` nearer its own worker, then as far from the taken slots as
    that allows."""
    chosen = choose_bearing(watch(k), taken, NEIGHBOURS)
    assert chosen == expected
    for b in slot_bearings(watch(k, chosen)):
        slot = (4 * math.cos(math.radians(b)), 4 * math.sin(math.radians(b)))
        assert math.dist(slot, (-6.0, 0.0)) >= 4 + CLEAR_M


def test_slots_follow_the_bearing_round_the_ring():
    assert slot_bearings(watch(3, 350.0)) == pytest.approx([350.0, 110.0, 230.0])


def submit(gs, action: MonitorAction, action_id: str):
    gs.manager.submit(SubmitAction(request_id=action_id, action=action, action_id=action_id))
    gs.settle()
    return gs.store.action(action_id)


def test_two_monitors_of_one_worker_send_their_uavs_to_opposite_sides(gs):
    first = submit(gs, watch(), "m1")
    second = submit(gs, watch(), "m2")
    other_worker = submit(gs, watch(worker="W1"), "m3")
    assert (first.action.bearing_deg, second.action.bearing_deg) == (0.0, 180.0)
    assert other_worker.action.bearing_deg == 0.0  # another worker's ring
    tasks = [t for p in gs.replanner.plans.values() for t in p.tasks if isinstance(t, MonitorTask)]
    bearings = {t.action_id: t.bearing_deg for t in tasks}
    assert bearings.get("m1") == 0.0 and bearings.get("m2") == 180.0


def test_a_repeated_request_without_a_bearing_is_the_same_request(gs):
    record = submit(gs, watch(), "m1")
    submit(gs, watch(), "m2")
    again = gs.manager.submit(SubmitAction(request_id="m2", action=watch(), action_id="m2"))
    assert again.action.bearing_deg == 180.0
    with pytest.raises(RequestError):  # the same id for another bearing: a conflict
        gs.manager.submit(SubmitAction(request_id="m2", action=watch(bearing=90.0)))
    assert record.action.bearing_deg == 0.0


def test_an_operator_bearing_is_kept_and_a_modify_keeps_the_chosen_one(gs):
    record = submit(gs, watch(bearing=45.0), "m1")
    assert record.action.bearing_deg == 45.0
    submit(gs, watch(), "m2")
    gs.manager.modify(ModifyAction(request_id="edit", action_id="m2", action=watch(k=2)))
    assert gs.store.action("m2").action.bearing_deg == 225.0


def _slot_of(task: MonitorTask) -> float:
    return (task.bearing_deg + 360.0 * task.slot / task.slots) % 360.0


def _watching(gs, action_id: str) -> list[MonitorTask]:
    return [
        t
        for p in gs.replanner.plans.values()
        for t in p.tasks
        if isinstance(t, MonitorTask) and t.action_id == action_id
    ]


@pytest.mark.parametrize(("k", "airborne"), [(1, True), (2, True), (1, False)])
def test_a_slot_whose_uav_was_lost_in_the_air_is_moved_clear_of_it(gs, k, airborne):
    """A hung agent's autopilot hovers on at its slot: the replacement is
    sent to a slot the farthest from it (and from the action's other slots);
    a UAV lost on the ground leaves the slot where it is."""
    submit(gs, watch(k), "m1")
    [held, *_] = [t for t in _watching(gs, "m1") if t.slot == 0]
    victim = next(u for u, p in gs.replanner.plans.items() if held in p.tasks)
    flying = gs.telemetry(victim)
    if airborne:
        flying = msgspec.structs.replace(flying, flight_state=FlightState.FLYING)
    gs.monitor.on_telemetry(flying, gs.now)
    gs.monitor.on_status(
        AgentStatus(uav_id=victim, stamp_s=gs.now, state=AgentState.BUSY, task_id=held.task_id)
    )
    others = [u for u in ALL if u != victim]
    gs.monitor.on_token(victim, False, gs.now)
    gs.advance(6.0)
    gs.heartbeat(*others)
    gs.advance(0.1)
    after = _watching(gs, "m1")
    replacement = [t for t in after if t.slot == 0]
    assert replacement and victim not in {
        u for u, p in gs.replanner.plans.items() if replacement[0] in p.tasks
    }
    moved = _slot_of(replacement[0])
    if not airborne:
        assert moved == _slot_of(held)
        return
    expected = 180.0 if k == 1 else 90.0  # k = 2: clear of the lost UAV and of slot 1
    assert moved == expected
    assert sorted({_slot_of(t) for t in after}) == sorted({expected, *([180.0] if k == 2 else [])})
    assert gs.store.action("m1").slot_bearings_deg == {0: expected}
