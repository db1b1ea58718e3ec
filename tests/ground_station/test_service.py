"""The ground-station process over a real router, with a real SQLite file and
scripted agents: plans reach agents, drop-outs, stale outcomes, kill -9 and
restart, hostile RPC payloads."""

from __future__ import annotations

import sys
import time
import types
import typing
from collections.abc import Iterable
from unittest import mock

import pytest

from ground_station.service import GroundStation
from linecrew.bench.light_agent import LightAgent
from linecrew_runtime.bus import Bus
from linecrew_runtime.scenarios import load
from proto import (
    ActionList,
    ActionReply,
    ActionState,
    AgentState,
    AgentStatus,
    EventKind,
    GetAction,
    GetHistory,
    GetMetrics,
    GetPlans,
    HistoryReply,
    InspectTask,
    KeySpace,
    ListActions,
    MetricsReply,
    OutcomeResult,
    PickTask,
    PlansReply,
    RequestError,
    Role,
    SubmitAction,
    TaskOutcome,
    Traffic,
    UavTopic,
)
from proto.errors import LinecrewError
from proto.rpc import Request
from tests.support.processes import running, start, wait_until

SCENARIO = load("paper")
KEYS = KeySpace(SCENARIO.site.id)
UAVS = [u.id for u in SCENARIO.fleet.uavs]
LINK_TIMEOUT_S = 2.0


def gs_args(router: str, db: str) -> list[str]:
    return [
        sys.executable,
        "-m",
        "ground_station",
        "--connect",
        router,
        "--db",
        db,
        "--link-timeout",
        str(LINK_TIMEOUT_S),
        "--lease-ms",
        "500",
    ]


@pytest.fixture
def client(bus_config):
    with Bus.open(bus_config) as bus:
        yield bus


def gs_alive(client: Bus) -> bool:
    return bool(client.alive(KEYS.all_alive(Role.GROUND_STATION)))


@pytest.fixture
def gs(router, client, tmp_path):
    with running(gs_args(router, str(tmp_path / "gs.db")), "gs", lambda: gs_alive(client)) as p:
        yield p


def lost_uavs(client: Bus) -> list[str]:
    return [e.uav_id for e in history(client).events if e.kind == EventKind.UAV_LOST]


def settled(client: Bus) -> bool:
    """Whether the gs's plan is final for now (improvement included)."""
    metrics = client.query(KEYS.rpc("metrics"), GetMetrics(), MetricsReply, 5.0)
    return metrics.values.get("planner_settled") == 1.0


@pytest.fixture
def agents(bus_config, gs):
    fleet = {u: LightAgent(bus_config, SCENARIO, u) for u in UAVS}
    try:
        wait_until(lambda: all(a.plans for a in fleet.values()), 15, "a first plan for every UAV")
        yield fleet
    finally:
        for agent in fleet.values():
            agent.close()


def submit(client: Bus, name: str) -> ActionReply:
    scripted = next(a for a in SCENARIO.actions if a.id == name)
    request = SubmitAction(request_id=f"r-{name}", action=scripted.action, action_id=name)
    return client.query(KEYS.rpc("submit"), request, ActionReply, 5.0)


def history(client: Bus) -> HistoryReply:
    return client.query(KEYS.rpc("history"), GetHistory(limit=1000), HistoryReply, 5.0)


def waypoints_of(agents: Iterable[LightAgent], action_id: str) -> set[int]:
    """The waypoint indices of inspection ``action_id`` in the agents' latest plans."""
    return {
        w.index
        for agent in agents
        if (plan := agent.latest())
        for t in plan.tasks
        if isinstance(t, InspectTask) and t.action_id == action_id
        for w in t.waypoints
    }


def owner_of(agents: dict[str, LightAgent], action_id: str) -> LightAgent | None:
    for agent in agents.values():
        plan = agent.latest()
        if plan and any(t.action_id == action_id for t in plan.tasks):
            return agent
    return None


def test_a_new_action_reaches_the_capable_agent(client, agents):
    reply = submit(client, "deliver-wrench")
    assert reply.record.state == ActionState.ACCEPTED  # durable; the plan follows
    wait_until(
        lambda: (
            client.query(
                KEYS.rpc("get_action"), GetAction(action_id="deliver-wrench"), ActionReply, 5.0
            ).record.state
            == ActionState.PLANNED
        ),
        10,
        "the action planned",
    )
    uav1 = agents["uav-1"]
    wait_until(
        lambda: uav1.latest().tasks and isinstance(uav1.latest().tasks[0], PickTask),
        10,
        "the pick task at uav-1",
    )
    assert owner_of(agents, "deliver-wrench") is uav1


def test_the_ground_station_tells_agents_where_every_uav_is(client, agents):
    reports: list[Traffic] = []
    client.subscribe(KEYS.traffic(), Traffic, lambda _key, report: reports.append(report))
    wait_until(lambda: reports and len(reports[-1].uavs) == len(agents), 10, "a traffic report")
    entry = next(e for e in reports[-1].uavs if e.uav_id == "uav-1")
    assert entry.position == agents["uav-1"].position and not entry.airborne
    assert entry.age_s < 1.0  # heard 5 times a second


def test_brief_drop_out_changes_nothing_and_a_long_one_moves_the_work(client, agents):
    submit(client, "inspect-loop")
    wait_until(lambda: owner_of(agents, "inspect-loop"), 10, "inspection planned")
    wait_until(lambda: settled(client), 30, "the background improvement done")
    victim = owner_of(agents, "inspect-loop")
    victim.go_silent()
    time.sleep(LINK_TIMEOUT_S / 4)  # well inside the grace: must change nothing
    victim.speak_again()
    events = history(client).events
    assert not [e for e in events if e.kind == EventKind.UAV_LOST]
    victim.go_silent()
    share = waypoints_of([victim], "inspect-loop")
    others = [a for a in agents.values() if a is not victim]
    wait_until(lambda: share <= waypoints_of(others, "inspect-loop"), 15, "work moved")
    assert lost_uavs(client) == [victim.uav_id]
    victim.speak_again()
    moved_epoch = max(a.latest().epoch for a in others)
    wait_until(lambda: victim.latest().epoch > moved_epoch, 15, "a fresh plan for the returner")


def test_stale_outcomes_are_recorded_but_do_not_change_state(client, agents):
    submit(client, "inspect-loop")
    wait_until(lambda: owner_of(agents, "inspect-loop"), 10, "inspection planned")
    owner = owner_of(agents, "inspect-loop")
    task = next(t for t in owner.latest().tasks if isinstance(t, InspectTask))
    impostor = next(a for a in agents.values() if a is not owner)
    impostor.bus.publish(
        KEYS.outcome(impostor.uav_id),
        TaskOutcome(
            uav_id=impostor.uav_id,
            task_id=task.task_id,
            epoch=owner.latest().epoch,
            result=OutcomeResult.COMPLETED,
            waypoints_done=list(range(8)),
        ),
    )
    wait_until(
        lambda: any(
            e.kind == EventKind.FAULT and "stale" in e.detail for e in history(client).events
        ),
        10,
        "stale outcome recorded",
    )
    actions = client.query(KEYS.rpc("list_actions"), ListActions(), ActionList, 5.0)
    assert [r.state for r in actions.records] == [ActionState.PLANNED]


def test_a_sample_whose_uav_disagrees_with_its_key_is_dropped_and_counted(client, agents):
    """uav-2 publishing on its own key as uav-1: a completed delivery, an
    emergency status and crashed telemetry of uav-1 change nothing."""
    submit(client, "deliver-wrench")
    uav1, uav2 = agents["uav-1"], agents["uav-2"]
    wait_until(lambda: owner_of(agents, "deliver-wrench") is uav1, 10, "the delivery at uav-1")
    plan = uav1.latest()
    for task in plan.tasks:
        spoof = TaskOutcome(
            uav_id="uav-1",
            task_id=task.task_id,
            action_id=task.action_id,
            epoch=plan.epoch,
            result=OutcomeResult.COMPLETED,
            tool="wrench",
        )
        uav2.bus.publish(KEYS.outcome("uav-2"), spoof)
    status = AgentStatus(uav_id="uav-1", stamp_s=time.time(), state=AgentState.EMERGENCY)
    uav2.bus.publish(KEYS.uav("uav-2", UavTopic.STATUS), status)

    def mismatches() -> float:
        metrics = client.query(KEYS.rpc("metrics"), GetMetrics(), MetricsReply, 5.0)
        return metrics.values["bus_identity_mismatch"]

    wait_until(lambda: mismatches() >= len(plan.tasks) + 1, 10, "the spoofed samples counted")
    record = client.query(
        KEYS.rpc("get_action"), GetAction(action_id="deliver-wrench"), ActionReply, 5.0
    ).record
    assert record.state == ActionState.PLANNED  # not completed by uav-2's word
    assert owner_of(agents, "deliver-wrench") is uav1  # its work was not taken away
    assert not [e for e in history(client).events if e.kind == EventKind.UAV_LOST]


def test_a_sample_stamped_far_in_the_future_is_dropped_and_counted(client, agents):
    submit(client, "deliver-wrench")
    uav1 = agents["uav-1"]
    wait_until(lambda: owner_of(agents, "deliver-wrench") is uav1, 10, "the delivery at uav-1")
    ahead = time.time() + 3600  # on its own key, but an hour ahead of the mission clock
    status = AgentStatus(uav_id="uav-1", stamp_s=ahead, state=AgentState.EMERGENCY)
    uav1.bus.publish(KEYS.uav("uav-1", UavTopic.STATUS), status)

    def dropped() -> float:
        metrics = client.query(KEYS.rpc("metrics"), GetMetrics(), MetricsReply, 5.0)
        return metrics.values["bus_future_stamps"]

    wait_until(lambda: dropped() >= 1, 10, "the future-stamped status counted")
    assert owner_of(agents, "deliver-wrench") is uav1  # the forged emergency took nothing


def test_a_uav_reads_only_its_own_plan(client, agents):
    submit(client, "deliver-wrench")
    wait_until(lambda: agents["uav-1"].latest().tasks, 10, "uav-1 has work")
    own = client.query(KEYS.plan("uav-1"), GetPlans(uav_id="uav-1"), PlansReply, 5.0)
    assert [p.uav_id for p in own.plans] == ["uav-1"]
    with pytest.raises(RequestError) as refused:
        client.query(KEYS.plan("uav-2"), GetPlans(uav_id="uav-1"), PlansReply, 5.0)
    assert refused.value.code == "forbidden"
    with pytest.raises(LinecrewError):  # a wildcard query is no UAV's
        client.query(KEYS.all_uavs(UavTopic.PLAN), GetPlans(), PlansReply, 5.0)


def test_kill_9_and_restart_loses_nothing_accepted(router, client, agents, gs, tmp_path):
    for name in ("deliver-wrench", "inspect-loop", "monitor-w2"):
        submit(client, name)
    before = {a.uav_id: a.latest().epoch for a in agents.values()}
    gs.kill()
    wait_until(lambda: not gs_alive(client), 10, "ground station gone")
    restarted = start(gs_args(router, str(tmp_path / "gs.db")), "gs-restarted")
    try:
        wait_until(lambda: gs_alive(client), 20, "ground station back")
        actions = client.query(KEYS.rpc("list_actions"), ListActions(), ActionList, 5.0)
        assert {r.action_id for r in actions.records} == {
            "deliver-wrench",
            "inspect-loop",
            "monitor-w2",
        }
        wait_until(
            lambda: all(a.latest().epoch > before[a.uav_id] for a in agents.values()),
            15,
            "fresh plans with higher epochs",
        )
        planned = {t.action_id for a in agents.values() for t in a.latest().tasks}
        assert {"deliver-wrench", "inspect-loop", "monitor-w2"} <= planned
    finally:
        assert restarted.stop() == 0, restarted.output()


def test_every_request_of_the_contract_has_one_answer_in_the_dispatch_table():
    stand_in = types.SimpleNamespace(manager=mock.Mock(), metrics=dict)
    assert set(GroundStation.answers(stand_in)) == set(typing.get_args(Request))


@pytest.mark.parametrize("payload", [b"", b"\xc1", b"\x81\xa4type\xa6submit", b"x" * 5000])
def test_hostile_rpc_payloads_get_error_replies_and_the_gs_keeps_serving(client, gs, payload):
    for op in ("submit", "cancel", "history"):
        replies = list(client.session.get(KEYS.rpc(op), payload=payload, timeout=5.0))
        assert len(replies) == 1 and replies[0].err is not None
    with pytest.raises(RequestError) as caught:
        client.query(KEYS.rpc("cancel"), GetHistory(), HistoryReply, 5.0)
    assert caught.value.code == "decode_error"  # each key decodes its own request type only
    metrics = client.query(KEYS.rpc("metrics"), GetMetrics(), MetricsReply, 5.0)
    assert "replans" in metrics.values
    assert gs.popen.poll() is None


def test_an_invalid_submission_names_the_field(client, gs):
    bad = SubmitAction(
        request_id="bad",
        action=SCENARIO.actions[2].action.__class__(worker_id="nobody", duration_s=5),
    )
    with pytest.raises(RequestError) as caught:
        client.query(KEYS.rpc("submit"), bad, ActionReply, 5.0)
    assert (caught.value.code, caught.value.field) == ("invalid_action", "action.worker_id")


def test_sigterm_stops_the_ground_station_cleanly(gs):
    assert gs.stop() == 0
    assert "ground station stopped on SIGTERM" in gs.output()
