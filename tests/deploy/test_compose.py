"""The fleet as deployed by docker-compose.yml, ten times faster than real
time, under real failures: the paper's scenario through REST, an agent's
container cut off the network (shorter and longer than the ground station's
link timeout), the ground station's and the router's processes crashed (their
restart policies bring them back: no step of the test starts them). One
compose project serves every test of this module; the missions run first,
since a mission ends only when every action has ended."""

from __future__ import annotations

import io
import sys
import time

import msgspec
import pytest
from rich.console import Console

from linecrew.client.gateway import Gateway
from linecrew.launch.demo import TERMINAL, run_mission
from linecrew_runtime.process import Shutdown
from linecrew_runtime.scenarios import load
from proto.mission import DeliverAction
from proto.scenario import Scenario
from tests.deploy.compose import AGENTS, Stack, poll
from tests.deploy.conftest import SPEEDUP

pytestmark = pytest.mark.deploy

PAPER = load("paper")
MISSION_TIMEOUT_S = 300.0
LINK_TIMEOUT_S = 5.0  # the ground station's default (docker-compose.yml)
# Longer than the Zenoh lease (1 s: the agent's session drops and comes back),
# shorter than the agent's 3 s and the ground station's 5 s link timeouts.
SHORT_CUT_S = 1.5
LONG_CUT_S = 9.0  # well beyond both


def renamed(scenario: Scenario, prefix: str, tool: str) -> Scenario:
    """The scenario with fresh action ids, to fly it again on the same stack;
    deliveries bring ``tool`` (from its own station): the first flight used
    the site's only wrench, and a delivered tool stays with the worker."""
    actions = []
    for scripted in scenario.actions:
        action = scripted.action
        if isinstance(action, DeliverAction):
            action = msgspec.structs.replace(action, tool=tool, tool_station_id=f"tp-{tool}")
        actions.append(
            msgspec.structs.replace(scripted, id=f"{prefix}-{scripted.id}", action=action)
        )
    return msgspec.structs.replace(scenario, actions=actions)


def fly(stack: Stack, scenario: Scenario, on_tick=None) -> dict[str, str]:
    """Submit the scenario's actions on time through REST (as ``linecrew
    demo``) and follow them until all end; action id -> final state."""
    gateway = Gateway(stack.url, stack.token)
    console = Console(file=io.StringIO())
    records, _ = run_mission(
        gateway, scenario, SPEEDUP, MISSION_TIMEOUT_S, Shutdown(), console, on_tick
    )
    ids = {a.id for a in scenario.actions}
    return {r["action_id"]: r["state"] for r in records if r["action_id"] in ids}


def monitoring(stack: Stack, action_id: str, duration_s: float) -> str:
    """Submit a 1-UAV monitoring of W2; return the UAV once it monitors."""
    stack.call(
        "POST",
        "/v1/actions",
        json={
            "type": "monitor",
            "worker_id": "W2",
            "uavs": 1,
            "standoff_m": 4,
            "duration_s": duration_s,
            "priority": 3,
            "action_id": action_id,
            "request_id": action_id,
        },
    )

    def monitoring_uav() -> str | None:
        for uav, record in stack.fleet().items():
            status = record["status"] or {}
            if (status.get("task_id") or "").startswith(f"{action_id}.") and status["progress"] > 0:
                return uav
        return None

    return poll(monitoring_uav, 90, f"{action_id} under way")


def events_of(stack: Stack, after_seq: int, kind: str, uav: str) -> list[dict]:
    return [e for e in stack.events(after_seq) if e["kind"] == kind and e["uav_id"] == uav]


def epoch(stack: Stack, uav: str) -> int:
    """The plan epoch the agent reports holding."""
    return stack.fleet()[uav]["status"]["epoch"]


def completed(stack: Stack, action_id: str) -> bool:
    state = stack.actions()[action_id]["state"]
    assert state not in TERMINAL - {"completed"}, f"{action_id} ended {state}"
    return state == "completed"


def test_the_papers_scenario_completes_in_containers(fleet):
    assert fly(fleet, PAPER) == {a.id: "completed" for a in PAPER.actions}


def test_killing_the_ground_station_mid_mission_loses_no_action(fleet):
    scenario = renamed(PAPER, "gs-kill", "hammer")
    ids = {a.id for a in scenario.actions}
    killed: dict[str, object] = {}

    def kill_once(mission_s: float, records: list[dict]) -> None:
        states = {r["action_id"]: r["state"] for r in records if r["action_id"] in ids}
        under_way = any(r["progress"] > 0 for r in records if r["action_id"] in ids)
        if killed or len(states) < len(ids) or not under_way:
            return
        before = fleet.restarts("ground-station")
        fleet.crash("ground-station")  # no one starts it again: its restart policy does
        poll(lambda: fleet.restarts("ground-station") > before, 60, "ground station restarted")
        poll(lambda: fleet.healthz()["ground_station"] == "up", 60, "ground station back")
        after = poll(fleet.actions, 30, "actions readable again")
        assert set(states) <= set(after), "an accepted action was lost"
        killed.update(at_s=mission_s, states=states)

    assert fly(fleet, scenario, kill_once) == {i: "completed" for i in ids}
    assert killed, "the ground station was never killed"


def test_a_cut_shorter_than_the_link_timeout_changes_nothing(fleet):
    uav = monitoring(fleet, "cut-short", duration_s=150)
    mark, epoch_before = fleet.last_seq(), epoch(fleet, uav)
    fleet.container(f"agent-{uav}")  # looked up before the clock starts

    cut = time.monotonic()
    fleet.disconnect(f"agent-{uav}")
    time.sleep(SHORT_CUT_S)  # the partition itself
    fleet.connect(f"agent-{uav}")
    cut_s = time.monotonic() - cut  # an upper bound: both docker commands included
    sys.stderr.write(f"short cut of {uav}: at most {cut_s:.2f} s\n")
    assert cut_s < LINK_TIMEOUT_S - 1, f"the cut took {cut_s:.1f} s: docker too slow to test"
    # Watch past the moment the ground station would have declared it lost.
    time.sleep(max(0.0, LINK_TIMEOUT_S + 2 - (time.monotonic() - cut)))

    seen = [(e["kind"], e["uav_id"], e["detail"]) for e in fleet.events(mark)]
    assert not [e for e in seen if e[0] in {"uav_lost", "uav_back"} and e[1] == uav], seen
    assert epoch(fleet, uav) >= epoch_before
    # Nothing lost: the monitoring goes on to its end (possibly handed over
    # for battery reasons, which have nothing to do with the cut).
    poll(lambda: completed(fleet, "cut-short"), 120, "cut-short completed")


def test_a_cut_longer_than_the_link_timeout_moves_the_work(fleet):
    uav = monitoring(fleet, "cut-long", duration_s=250)
    mark, epoch_before = fleet.last_seq(), epoch(fleet, uav)

    fleet.disconnect(f"agent-{uav}")
    try:
        cut = time.monotonic()
        poll(lambda: events_of(fleet, mark, "uav_lost", uav), 20, f"{uav} lost")
        sys.stderr.write(f"long cut of {uav}: lost after {time.monotonic() - cut:.1f} s\n")
        others = poll(
            lambda: fleet.assignees("cut-long") - {uav}, 20, "cut-long replanned to another UAV"
        )
        time.sleep(max(0.0, LONG_CUT_S - (time.monotonic() - cut)))
    finally:
        fleet.connect(f"agent-{uav}")

    poll(lambda: events_of(fleet, mark, "uav_back", uav), 30, f"{uav} back")
    poll(lambda: epoch(fleet, uav) > epoch_before, 30, f"{uav} holds a newer plan")
    assert others
    # Not flown twice: the cut-off agent gave its watch up on its own (it reports
    # the task failed once it can talk again; the ground station had already
    # moved it, so the report is recorded as stale and changes nothing).
    poll(
        lambda: [
            e
            for e in events_of(fleet, mark, "fault", uav)
            if "stale outcome cut-long" in e["detail"] and "failed" in e["detail"]
        ],
        30,
        f"{uav} reports it abandoned cut-long",
    )
    poll(lambda: completed(fleet, "cut-long"), 180, "cut-long completed")


def test_everyone_recovers_from_a_router_crash(fleet):
    before = fleet.restarts("router")
    fleet.crash("router")  # no one starts it again: its restart policy does
    poll(lambda: fleet.restarts("router") > before and fleet.running("router"), 60, "router back")
    restarted_s = time.time() * SPEEDUP  # mission clock

    def fresh() -> bool:
        uavs = fleet.fleet()
        return set(uavs) == set(AGENTS) and all(
            u["state"] != "lost" and u["telemetry"]["stamp_s"] > restarted_s for u in uavs.values()
        )

    poll(fresh, 60, f"agents {', '.join(AGENTS)} present again with fresh telemetry")
    fleet.call(
        "POST",
        "/v1/actions",
        json={
            "type": "inspect",
            "waypoints": [{"position": {"x_m": 0, "y_m": 7, "z_m": 3}, "service_s": 5}],
            "action_id": "after-router",
            "request_id": "after-router",
        },
    )
    poll(lambda: fleet.assignees("after-router"), 30, "after-router planned")
    poll(lambda: completed(fleet, "after-router"), 120, "after-router completed")
