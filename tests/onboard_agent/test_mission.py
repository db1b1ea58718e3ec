"""The task queue: epoch fencing, plan validation, outcomes."""

from __future__ import annotations

from onboard_agent import Mission, PlanVerdict
from onboard_agent.mission import EPOCH_LEAD
from proto.plan import DeliverTask, GoHomeTask, InspectTask, MonitorTask, PickTask, RechargeTask
from proto.telemetry import OutcomeResult
from tests.onboard_agent.helpers import SCENARIO, inspect_task, plan, point


def mission() -> Mission:
    return Mission("uav-1", SCENARIO.site, lambda: 1.7e9)


class TestEpochFencing:
    def test_newer_epoch_replaces_the_queue(self):
        m = mission()
        assert m.offer(plan(inspect_task("a"), epoch=1)) is PlanVerdict.ACCEPTED
        assert m.offer(plan(inspect_task("b"), epoch=2)) is PlanVerdict.ACCEPTED
        assert [t.task_id for t in m.tasks] == ["b"] and m.epoch == 2

    def test_older_and_equal_epochs_are_ignored(self):
        m = mission()
        m.offer(plan(inspect_task("a"), epoch=5))
        assert m.offer(plan(inspect_task("b"), epoch=4)) is PlanVerdict.STALE
        assert m.offer(plan(inspect_task("c"), epoch=5)) is PlanVerdict.STALE
        assert [t.task_id for t in m.tasks] == ["a"] and m.epoch == 5
        assert m.take_outcomes() == []

    def test_an_epoch_far_ahead_of_the_announced_one_is_held_until_announced(self):
        m = mission()
        m.announce("gs-a", 10)
        forged = plan(inspect_task("x"), epoch=2**52)  # would fence out every real plan
        assert m.offer(forged) is PlanVerdict.UNANNOUNCED and m.epoch == 0
        assert m.offer(plan(inspect_task("a"), epoch=11)) is PlanVerdict.ACCEPTED
        assert m.announce("gs-a", 12) is None  # the held plan waits for its epoch...
        assert (
            m.offer(plan(inspect_task("b"), epoch=12 + EPOCH_LEAD + 5)) is PlanVerdict.UNANNOUNCED
        )
        assert m.announce("gs-a", 13) is None  # ...still not covered: held
        assert [t.task_id for t in m.tasks] == ["a"] and m.epoch == 11

    def test_a_held_plan_is_adopted_once_an_announcement_covers_it(self):
        m = mission()  # a restarted agent: nothing announced yet
        assert m.offer(plan(inspect_task("a"), epoch=500)) is PlanVerdict.UNANNOUNCED
        assert m.announce("gs-b", 500) is PlanVerdict.ACCEPTED
        assert [t.task_id for t in m.tasks] == ["a"] and m.epoch == 500

    def test_plan_for_another_uav_is_rejected_with_failures(self):
        m = mission()
        verdict = m.offer(plan(inspect_task("a"), inspect_task("b"), uav_id="uav-2", epoch=3))
        assert verdict is PlanVerdict.REJECTED
        assert m.head is None and m.epoch == 0
        outcomes = m.take_outcomes()
        assert [(o.task_id, o.result) for o in outcomes] == [
            ("a", OutcomeResult.FAILED),
            ("b", OutcomeResult.FAILED),
        ]
        assert all("uav-2" in o.reason and o.uav_id == "uav-1" for o in outcomes)

    def test_replacing_a_started_task_reports_it_aborted(self):
        m = mission()
        m.offer(plan(inspect_task("a"), epoch=1))
        m.start(m.head)
        m.offer(plan(inspect_task("b"), epoch=2))
        [outcome] = m.take_outcomes()
        assert (outcome.task_id, outcome.result, outcome.epoch) == ("a", "aborted", 1)

    def test_a_task_kept_by_the_new_plan_keeps_its_progress(self):
        m = mission()
        m.offer(plan(inspect_task("a"), epoch=1))
        m.start(m.head)
        m.mark_waypoint(m.head, 0)
        m.offer(plan(inspect_task("a"), epoch=2))
        assert m.take_outcomes() == []
        assert m.next_waypoint(m.head).index == 1


class TestBadPlans:
    def test_bad_tasks_fail_and_good_ones_stay(self):
        m = mission()
        bad = [
            InspectTask(task_id="empty", waypoints=[]),
            RechargeTask(task_id="nowhere", station_id="C9", position=point(0, 0)),
            GoHomeTask(task_id="home9", station_id="H9", position=point(0, 0)),
            MonitorTask(
                task_id="ghost", worker_id="W9", slot=0, slots=1, standoff_m=3, duration_s=10
            ),
            MonitorTask(
                task_id="slot", worker_id="W1", slot=2, slots=2, standoff_m=3, duration_s=10
            ),
            PickTask(task_id="rack", tool="x", tool_station_id="nope", position=point(0, 0)),
            DeliverTask(task_id="who", tool="x", worker_id="W0"),
        ]
        assert m.offer(plan(inspect_task("ok"), *bad)) is PlanVerdict.ACCEPTED
        assert [t.task_id for t in m.tasks] == ["ok"]
        reasons = {o.task_id: o.reason for o in m.take_outcomes()}
        assert set(reasons) == {t.task_id for t in bad}
        assert "without waypoints" in reasons["empty"]
        assert "unknown station 'C9'" in reasons["nowhere"]
        assert "unknown worker 'W9'" in reasons["ghost"]
        assert "unknown tool station" in reasons["rack"]


def test_abandon_fails_every_task_with_progress():
    m = mission()
    m.offer(plan(inspect_task("a"), inspect_task("b")))
    m.mark_waypoint(m.head, 0)
    assert m.abandon("emergency: test") == 2
    outcomes = m.take_outcomes()
    assert [o.result for o in outcomes] == ["failed", "failed"]
    assert outcomes[0].waypoints_done == [0]
    assert outcomes[0].progress == 1 / 3
    assert m.head is None


def test_recently_sent_outcomes_are_queued_again_after_each_reconnect():
    m = mission()
    m.offer(plan(inspect_task("a"), inspect_task("b")))
    m.abandon("emergency: test")
    sent = m.take_outcomes()
    assert m.take_outcomes() == []
    m.redeliver()  # the ground station's token came back: they may have been lost
    assert m.take_outcomes() == sent
    m.redeliver()
    assert [o.task_id for o in m.take_outcomes()] == [o.task_id for o in sent]
    m.take_outcomes()
    assert m.take_outcomes() == []
