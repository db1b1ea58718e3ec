"""Monitoring Task Tree: the slot's stand-off point, following the worker."""

from __future__ import annotations

import math

import msgspec
import pytest

from ground_station.planner.validate import WAIT_ASIDE_M
from proto.geo import GeoPoint
from proto.plan import MonitorTask, WaitTask
from proto.telemetry import HumanPose, OutcomeResult, Traffic, TrafficEntry
from tests.onboard_agent.helpers import SCENARIO, Rig, plan, point

W2 = SCENARIO.site.worker("W2").position  # (-5, 15, 3)


def monitor(slot: int = 1, slots: int = 4, duration_s: float = 3.0) -> MonitorTask:
    return MonitorTask(
        task_id="m1", worker_id="W2", slot=slot, slots=slots, standoff_m=4.0, duration_s=duration_s
    )


def last_goto(rig):
    return [arg for name, arg in rig.autopilot.calls if name == "goto"][-1]


def test_holds_the_slot_point_for_the_duration():
    rig = Rig()
    rig.agent.offer_plan(plan(monitor(slot=1, slots=4)))
    rig.run_until(lambda: rig.leaf() == "Monitoring")
    target = last_goto(rig)
    angle = 2 * math.pi * 1 / 4
    assert target.x_m == pytest.approx(W2.x_m + 4 * math.cos(angle))
    assert target.y_m == pytest.approx(W2.y_m + 4 * math.sin(angle))
    rig.tick(20)
    assert rig.mission.head is not None
    assert rig.agent.status().progress == pytest.approx(2.0 / 3.0, abs=0.05)
    rig.run_until(lambda: rig.mission.head is None, max_ticks=20)
    [outcome] = rig.outcomes()
    assert outcome.result is OutcomeResult.COMPLETED


def test_follows_the_worker_when_they_move():
    rig = Rig()
    rig.agent.offer_plan(plan(monitor(slot=0, slots=1, duration_s=30.0)))
    rig.run_until(lambda: rig.leaf() == "Monitoring")
    moved = point(5.0, 15.0, 3.0)
    rig.agent.human_pose(
        HumanPose(worker_id="W2", stamp_s=rig.wall(), position=moved, geo=GeoPoint())
    )
    rig.tick(arrive=False)
    target = last_goto(rig)
    assert (target.x_m, target.y_m) == pytest.approx((9.0, 15.0))


def test_time_monitored_survives_an_interruption():
    rig = Rig()
    rig.agent.offer_plan(plan(monitor(duration_s=10.0)))
    rig.run_until(lambda: rig.leaf() == "Monitoring")
    rig.tick(30)
    done = rig.mission.monitored_s("m1")
    rig.autopilot.update(position=point(20.0, 20.0, 3.0))  # blown away
    rig.tick(arrive=False)
    assert rig.leaf() == "Go near Human Target"
    rig.run_until(lambda: rig.leaf() == "Monitoring")
    assert rig.mission.monitored_s("m1") >= done


def test_stale_poses_are_ignored():
    rig = Rig()
    new = HumanPose(worker_id="W2", stamp_s=10.0, position=point(1, 1, 3), geo=GeoPoint())
    old = HumanPose(worker_id="W2", stamp_s=5.0, position=point(9, 9, 3), geo=GeoPoint())
    rig.agent.human_pose(new)
    rig.agent.human_pose(old)
    assert rig.agent.ctx.surroundings.worker_position("W2") == point(1, 1, 3)


def test_a_pose_stamped_from_the_future_is_refused_and_later_real_poses_still_count():
    rig = Rig()
    surroundings = rig.agent.ctx.surroundings
    forged = HumanPose(
        worker_id="W2", stamp_s=rig.wall() + 3600, position=point(9, 9, 3), geo=GeoPoint()
    )
    rig.agent.human_pose(forged)
    real = HumanPose(worker_id="W2", stamp_s=rig.wall(), position=point(1, 1, 3), geo=GeoPoint())
    rig.agent.human_pose(real)
    assert surroundings.worker_position("W2") == point(1, 1, 3) and surroundings.refused == 1


def test_a_timed_segment_holds_clear_of_the_slot_until_its_window_then_leaves_at_its_end():
    rig = Rig()
    start = rig.wall() + 5.0  # the UAV it relieves holds the slot until then
    task = msgspec.structs.replace(
        monitor(slot=0, slots=1, duration_s=4.0), start_s=rig.wall(), end_s=start + 4.0
    )
    rig.agent.offer_plan(plan(task))
    rig.run_until(lambda: rig.leaf() == "Monitoring")
    held = last_goto(rig)
    assert held.x_m == pytest.approx(W2.x_m + 4.0 + rig.agent.ctx.config.handover_hold_m)
    assert held.z_m == pytest.approx(W2.z_m + task.height_m)  # above the worker, not beside
    rig.run_until(lambda: rig.wall() >= start + 0.5)
    assert last_goto(rig).x_m == pytest.approx(W2.x_m + 4.0)  # closes in once it is its turn
    assert rig.mission.head is not None
    rig.run_until(lambda: rig.mission.head is None)
    assert rig.wall() >= start + 4.0 - 0.2  # left at the window's end, not before
    [outcome] = rig.outcomes()
    assert outcome.result is OutcomeResult.COMPLETED
    assert outcome.flown_s == pytest.approx(4.0 - 0.5, abs=1.0)  # only seconds in the window


def test_a_wait_after_a_segment_hovers_aside_of_the_slot_clear_of_its_relief():
    rig = Rig()
    wait = WaitTask(task_id="w1", until_s=rig.wall() + 30.0)
    rig.agent.offer_plan(plan(monitor(slot=0, slots=1, duration_s=2.0), wait))
    rig.run_until(lambda: isinstance(rig.mission.head, WaitTask))
    rig.run_until(lambda: rig.leaf() == "Wait")
    aside = last_goto(rig)
    config = rig.agent.ctx.config
    # along the ring (counter-clockwise), at the slot's height
    assert (aside.x_m, aside.y_m) == pytest.approx((W2.x_m + 4.0, W2.y_m + config.wait_aside_m))
    # the relief comes in from handover_hold_m out on the bearing: its path stays clear
    relief_path = [(W2.x_m + 4.0 + f * config.handover_hold_m, W2.y_m) for f in (0, 0.5, 1)]
    assert min(math.dist((aside.x_m, aside.y_m), p) for p in relief_path) >= config.wait_aside_m
    assert config.wait_aside_m == WAIT_ASIDE_M  # the rule the planner's validator checks plans by
    rig.run_until(lambda: rig.mission.head is None)
    assert [o.result for o in rig.outcomes()] == [OutcomeResult.COMPLETED] * 2


def test_a_wait_that_follows_no_segment_holds_where_it_is():
    rig = Rig()
    rig.agent.offer_plan(plan(WaitTask(task_id="w1", until_s=rig.wall() + 3.0)))
    rig.run_until(lambda: rig.mission.head is None)
    assert not [name for name, _ in rig.autopilot.calls if name == "goto"]


def _traffic_at(rig, where, airborne=True):
    report = Traffic(
        uavs=[TrafficEntry(uav_id="uav-2", position=where, airborne=airborne, age_s=0.2)]
    )
    rig.agent.ctx.traffic.update(report, rig.clock())


def test_the_slot_is_flown_to_only_once_the_uav_hovering_there_has_left():
    rig = Rig()
    rig.agent.offer_plan(plan(monitor(slot=0, slots=1, duration_s=3.0)))
    slot = point(W2.x_m + 4.0, W2.y_m, W2.z_m + 3.0)
    rig.run_until(lambda: rig.leaf() == "Go near Human Target", arrive=False)
    rig.tick(5, arrive=False)  # airborne now, on its way
    _traffic_at(rig, point(slot.x_m + 0.5, slot.y_m, slot.z_m))  # uav-2 hovers at the slot
    rig.tick(3, arrive=False)
    held = last_goto(rig)
    assert held.distance_to(slot) > 2.0  # holding off where it was, not at the slot
    feedback = [
        n.feedback_message for n in rig.agent.root.iterate() if n.name.startswith("Go near")
    ]
    assert "holding off: uav-2 is at the Human Target" in feedback
    assert rig.agent.status().holding_for == "uav-2"  # the operator sees why it waits
    _traffic_at(rig, point(slot.x_m + 0.5, slot.y_m, slot.z_m), airborne=False)  # it landed
    rig.run_until(lambda: rig.leaf() == "Monitoring")
    assert rig.agent.status().holding_for is None
    assert rig.autopilot.state.position.distance_to(slot) < 0.1
    rig.run_until(lambda: rig.mission.head is None)
    [outcome] = rig.outcomes()
    assert outcome.result is OutcomeResult.COMPLETED


def test_a_uav_unheard_at_the_point_is_waited_for_yield_max_s_then_the_task_fails_retryable():
    """Chaos seed 12: a UAV sent to a waypoint where one with a killed agent
    hovered on flew into it once ``yield_max_s`` had passed. It waits that
    long, then gives the task back (retryable, ``point_occupied``), never
    having flown to the point."""
    rig = Rig()
    rig.agent.offer_plan(plan(monitor(slot=0, slots=1, duration_s=3.0)))
    slot = point(W2.x_m + 4.0, W2.y_m, W2.z_m + 3.0)
    rig.run_until(lambda: rig.leaf() == "Go near Human Target", arrive=False)
    rig.tick(5, arrive=False)
    _traffic_at(rig, slot)  # heard there once, then never again: unheard after 1 s
    started = rig.clock()
    rig.tick(3, arrive=False)
    assert rig.agent.status().holding_for == "uav-2"
    seen: list = []
    rig.run_until(lambda: seen.extend(rig.outcomes()) or seen, arrive=False)
    [outcome] = seen
    assert outcome.result is OutcomeResult.FAILED and outcome.retryable
    assert outcome.reason_code == "point_occupied"
    assert rig.clock() - started >= rig.agent.ctx.config.yield_max_s
    assert rig.autopilot.target is None or rig.autopilot.target.distance_to(slot) > 2.0


def test_a_relief_waits_while_the_uav_it_relieves_is_heard_at_the_slot():
    """Chaos seed 16: a relief came down onto the UAV it relieved, still
    watching from the slot (their plans disagreed on when it ends). The
    relief holds off, past ``yield_max_s`` too, as long as that UAV is heard
    there, and closes in once it has left."""
    rig = Rig()
    start = rig.wall() + 5.0
    task = msgspec.structs.replace(
        monitor(slot=0, slots=1, duration_s=120.0), start_s=rig.wall(), end_s=start + 120.0
    )
    rig.agent.offer_plan(plan(task))
    slot = point(W2.x_m + 4.0, W2.y_m, W2.z_m + task.height_m)
    waited_until = start + rig.agent.ctx.config.yield_max_s + 5.0
    while rig.wall() < waited_until:
        _traffic_at(rig, slot)  # the relieved UAV, heard at the slot
        rig.tick(1)
    assert last_goto(rig).distance_to(slot) > rig.agent.ctx.config.keep_clear_m
    assert rig.agent.status().holding_for == "uav-2"
    _traffic_at(rig, point(slot.x_m, slot.y_m + 6.0, slot.z_m))  # it has left
    rig.run_until(lambda: rig.leaf() == "Monitoring")
    assert rig.autopilot.state.position.distance_to(slot) < 0.1


def _relieved_segment(rig, duration_s: float = 6.0) -> MonitorTask:
    return msgspec.structs.replace(
        monitor(slot=0, slots=1, duration_s=duration_s),
        start_s=rig.wall(),
        end_s=rig.wall() + duration_s,
        relieved_by="uav-2",
    )


def test_a_relieved_uav_watches_from_beside_its_slot_until_its_relief_is_there():
    rig = Rig()
    task = _relieved_segment(rig)
    rig.agent.offer_plan(plan(task))
    slot = point(W2.x_m + 4.0, W2.y_m, W2.z_m + task.height_m)
    config = rig.agent.ctx.config
    rig.run_until(lambda: rig.wall() >= task.end_s + 5.0)
    assert rig.mission.head == task  # its relief is late: it stays
    beside = last_goto(rig)
    assert math.hypot(beside.x_m - W2.x_m, beside.y_m - W2.y_m) == pytest.approx(4.0)  # on the ring
    assert beside.z_m == pytest.approx(slot.z_m)
    assert beside.distance_to(slot) == pytest.approx(config.wait_aside_m)  # the slot left free
    assert beside.distance_to(slot) > config.keep_clear_m  # so the relief does not hold off
    _traffic_at(rig, point(slot.x_m + config.handover_hold_m, slot.y_m, slot.z_m))  # closing in
    _traffic_at(rig, point(slot.x_m, slot.y_m, slot.z_m + 2.5))  # or coming down: not there yet
    rig.tick(5)
    assert rig.mission.head == task and last_goto(rig) == beside
    sent = len(rig.autopilot.calls)
    _traffic_at(rig, point(slot.x_m + 1.0, slot.y_m, slot.z_m))  # at the slot: it leaves
    rig.run_until(lambda: rig.mission.head is None)
    [outcome] = rig.outcomes()
    assert outcome.result is OutcomeResult.COMPLETED
    # it leaves from where it is: never back into the slot its relief closes in on (chaos
    # seed 11: a relieved UAV flew back to the slot and passed 0.98 m under its relief)
    back = [a for n, a in rig.autopilot.calls[sent:] if n == "goto" and a.distance_to(slot) < 2.0]
    assert back == []


def test_a_relief_that_never_comes_is_waited_for_at_most_relief_wait_s():
    rig = Rig()
    task = _relieved_segment(rig)
    rig.agent.offer_plan(plan(task))
    _traffic_at(rig, point(W2.x_m - 20.0, W2.y_m, W2.z_m + 3.0))  # uav-2, far away
    rig.run_until(lambda: rig.mission.head is None)
    waited = rig.wall() - task.end_s
    assert (
        rig.agent.ctx.config.relief_wait_s - 1.0
        <= waited
        <= rig.agent.ctx.config.relief_wait_s + 2.0
    )


def test_a_segment_naming_no_relief_ends_at_its_end():
    rig = Rig()
    task = msgspec.structs.replace(_relieved_segment(rig), relieved_by=None)
    rig.agent.offer_plan(plan(task))
    rig.run_until(lambda: rig.mission.head is None)
    assert rig.wall() - task.end_s <= 1.0


def test_telemetry_reports_the_target_the_autopilot_was_last_sent_to():
    rig = Rig()
    assert rig.agent.telemetry().target is None  # on its pad
    rig.agent.offer_plan(plan(monitor(slot=0, slots=1, duration_s=30.0)))
    rig.run_until(lambda: rig.leaf() == "Monitoring")
    assert rig.agent.telemetry().target == last_goto(rig)


def test_a_uav_no_longer_heard_is_kept_clear_of_at_the_target_it_flew_to():
    """A hung agent's autopilot flies on to its last target while the
    ground station still reports where it was last heard (seed 7 of the
    chaos runs: 2.4 m short of a point another UAV was then sent to)."""
    rig = Rig()
    rig.agent.offer_plan(plan(monitor(slot=0, slots=1, duration_s=3.0)))
    slot = point(W2.x_m + 4.0, W2.y_m, W2.z_m + 3.0)
    rig.run_until(lambda: rig.leaf() == "Go near Human Target", arrive=False)
    rig.tick(5, arrive=False)  # airborne, on its way
    short = point(slot.x_m + 2.4, slot.y_m, slot.z_m)
    heard = TrafficEntry(uav_id="uav-2", position=short, airborne=True, age_s=0.2, target=slot)
    rig.agent.ctx.traffic.update(Traffic(uavs=[heard]), rig.clock())
    rig.tick(2, arrive=False)
    assert rig.agent.status().holding_for == "uav-2"  # heard nearer, coming: it goes first
    bound = msgspec.structs.replace(heard, target=point(slot.x_m + 2.4, slot.y_m + 9.0, slot.z_m))
    rig.agent.ctx.traffic.update(Traffic(uavs=[bound]), rig.clock())
    rig.tick(2, arrive=False)
    assert rig.agent.status().holding_for is None
    unheard = msgspec.structs.replace(heard, age_s=5.0)
    rig.agent.ctx.traffic.update(Traffic(uavs=[unheard]), rig.clock())
    rig.tick(2, arrive=False)
    assert rig.agent.status().holding_for == "uav-2"
    assert last_goto(rig).distance_to(slot) > 2.0


MIDWAY = point(W2.x_m + 14.0, W2.y_m, W2.z_m + 3.0)  # on the straight way to W2's slot
FAR = point(W2.x_m + 14.0, W2.y_m + 20.0, W2.z_m + 3.0)


@pytest.mark.parametrize(
    ("entry", "climbs"),
    [
        ({"position": MIDWAY, "age_s": 0.2}, False),  # heard: it moves on
        ({"position": MIDWAY, "age_s": 5.0}, True),  # unheard, hovers there (seed 12)
        ({"position": MIDWAY, "target": FAR}, False),  # heard passing, bound elsewhere
        ({"position": MIDWAY, "target": MIDWAY}, True),  # heard hovering there (seed 14)
        ({"position": FAR, "target": MIDWAY}, True),  # heard flying there (seed 17)
    ],
)
def test_a_route_passes_over_where_another_uav_hovers_or_is_about_to(entry, climbs):
    """A UAV crossing beside W2 passed another closer than the separation:
    one whose agent hung (chaos seed 12), one watching W2 from its slot
    (seed 14), one arriving there (seed 17). The route climbs over where
    another UAV hovers or flies to, as over a person; where one heard on
    its way to elsewhere is now is not in the way."""
    rig = Rig(position=point(W2.x_m + 24.0, W2.y_m, W2.z_m + 3.0))
    rig.autopilot.update(flight_state=rig.autopilot.state.flight_state.FLYING, armed=True)
    rig.agent.offer_plan(plan(monitor(slot=0, slots=1, duration_s=30.0)))
    other = TrafficEntry(uav_id="uav-2", airborne=True, **entry)
    rig.agent.ctx.traffic.update(Traffic(uavs=[other]), rig.clock())
    rig.tick(2, arrive=False)
    leg = last_goto(rig)
    if climbs:
        assert (leg.x_m, leg.y_m) == pytest.approx((W2.x_m + 24.0, W2.y_m))  # up first
        assert leg.z_m >= MIDWAY.z_m + 2.0
    else:
        assert leg.x_m == pytest.approx(W2.x_m + 4.0)  # straight for the slot
