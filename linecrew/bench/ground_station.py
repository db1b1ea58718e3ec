"""``linecrew bench ground-station``: the ground station process measured
with N light agents over a real router on loopback.

0. Load: ``--preload`` actions (default 200) are submitted in a burst and
   planned (coalesced) before anything is measured, so that the events below
   meet a mission of that size in force.
1. Event -> new plan received: an operator submits an action; the time until
   every agent whose plan changed has received it (p50 / p99 over events).
   Submit reply: the time until the operator's submit is answered (the
   action durable, ``accepted``; planning follows), p50 / p99 over every
   submit, and for one ``--big-inspect``-waypoint inspection.
2. Plan stability: the plan epochs issued per submitted action (at most
   one per real trigger), the epochs of adopted background improvements,
   and per UAV per mission-minute over ``--steady-s`` seconds in which
   nothing happens (target 0).
3. Silence -> lost -> replan: an agent process is ``kill -9``ed; the time
   until the ground station announces it lost and replans, against the
   configured ``--link-timeout``.
"""

from __future__ import annotations

import argparse
import json
import pathlib
import random
import subprocess
import sys
import tempfile
import threading
import time

import msgspec

from linecrew.bench.child import wait_ready
from linecrew.bench.light_agent import LightAgent
from linecrew.bench.plan_stability import EventWatch, measure_stability, settle
from linecrew_runtime.bus import Bus, BusConfig
from linecrew_runtime.bus.router_process import router_process
from linecrew_runtime.latency import percentile_ms
from linecrew_runtime.scenarios import load, with_fleet_size
from proto import (
    ActionList,
    ActionReply,
    ActionState,
    EventKind,
    GetMetrics,
    InspectAction,
    KeySpace,
    ListActions,
    MetricsReply,
    Point,
    Role,
    Scenario,
    SubmitAction,
    WaypointSpec,
)


def random_inspection(rng: random.Random, points: int = 3) -> InspectAction:
    """An inspection of ``points`` random waypoints around the paper site's lines."""
    return InspectAction(
        waypoints=[
            WaypointSpec(
                position=Point(
                    x_m=rng.uniform(-15, 10), y_m=rng.uniform(0, 20), z_m=rng.uniform(3, 18)
                ),
                service_s=5.0,
            )
            for _ in range(points)
        ]
    )


def _inspection(rng: random.Random, index: int, points: int = 3) -> SubmitAction:
    return SubmitAction(request_id=f"bench-{index}", action=random_inspection(rng, points))


def _timed_submit(client: Bus, keys: KeySpace, request: SubmitAction, replies: list[float]) -> None:
    started = time.perf_counter()
    client.query(keys.rpc("submit"), request, ActionReply, 10.0)
    replies.append(time.perf_counter() - started)


def _preload(
    client: Bus, keys: KeySpace, count: int, seed: int, replies: list[float], timeout_s: float
) -> float:
    """Submit ``count`` actions in a burst; wait until none is ``accepted``
    any more. Returns the seconds from the first submit until then."""
    rng = random.Random(seed + 1000)
    started = time.perf_counter()
    for i in range(count):
        _timed_submit(client, keys, _inspection(rng, 100_000 + i), replies)
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        listed = client.query(
            keys.rpc("list_actions"), ListActions(states=[ActionState.ACCEPTED]), ActionList, 10.0
        )
        if not listed.records:
            break
        time.sleep(0.05)
    return time.perf_counter() - started


def _event_to_plan(
    client: Bus,
    keys: KeySpace,
    agents: dict[str, LightAgent],
    watch: EventWatch,
    events: int,
    seed: int,
    replies: list[float],
) -> list[float]:
    rng = random.Random(seed)
    latencies = []
    for i in range(events):
        started = time.perf_counter()
        _timed_submit(client, keys, _inspection(rng, i), replies)
        replan = watch.wait_for(lambda e: e.kind == EventKind.REPLAN, 10.0, since=started)
        if replan is None:
            continue
        epoch = replan[1].epoch
        if epoch is None:
            raise ValueError(f"replan event without an epoch: {replan[1]}")
        changed = [
            e.uav_id
            for _, e in watch.items
            if e.kind == EventKind.PLAN_CHANGED and e.epoch == epoch and e.uav_id is not None
        ]
        deadline = time.monotonic() + 10
        arrivals = []
        for uav_id in changed:
            agent = agents.get(uav_id)
            while agent and not any(p.epoch >= epoch for p in agent.plans):
                if time.monotonic() > deadline:
                    break
                time.sleep(0.001)
            if agent:
                arrivals += [
                    t for t, p in zip(agent.arrivals, agent.plans, strict=False) if p.epoch == epoch
                ]
        if arrivals:
            latencies.append(max(arrivals) - started)
    return latencies


def doomed_agent(endpoint: str, scenario_file: str, uav_id: str, lease_ms: int) -> None:
    """Child-process body: a light agent (token + 5 Hz telemetry) until killed."""
    scenario = msgspec.json.decode(pathlib.Path(scenario_file).read_bytes(), type=Scenario)
    agent = LightAgent(BusConfig(connect=(endpoint,), lease_ms=lease_ms), scenario, uav_id)
    print("ready", flush=True)
    threading.Event().wait()
    agent.close()


def _silence_to_lost(
    endpoint: str,
    scenario_file: str,
    uav_id: str,
    lease_ms: int,
    watch: EventWatch,
) -> dict[str, float]:
    code = (
        f"from linecrew.bench.ground_station import doomed_agent; "
        f"doomed_agent({endpoint!r}, {scenario_file!r}, {uav_id!r}, {lease_ms})"
    )
    child = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE)
    try:
        wait_ready(child)
        back = watch.wait_for(lambda e: e.kind == EventKind.UAV_BACK and e.uav_id == uav_id, 20)
        if back is None:
            raise RuntimeError(f"{uav_id} never came up")
        killed = time.perf_counter()
        child.kill()
        lost = watch.wait_for(lambda e: e.kind == EventKind.UAV_LOST and e.uav_id == uav_id, 30)
        replan = watch.wait_for(
            lambda e: e.kind == EventKind.REPLAN and f"{uav_id} lost" in e.detail, 30
        )
    finally:
        child.kill()
        child.wait()
    return {
        "lost_after_s": lost[0] - killed if lost else float("nan"),
        "replanned_after_s": replan[0] - killed if replan else float("nan"),
    }


def run(
    uavs: int,
    events: int,
    link_timeout_s: float,
    lease_ms: int,
    seed: int,
    steady_s: float = 20.0,
    preload: int = 200,
    big_inspect: int = 2000,
) -> dict:
    """Run the measurements; returns the numbers."""
    scenario = with_fleet_size(load("paper"), uavs + 1)
    keys = KeySpace(scenario.site.id)
    with tempfile.TemporaryDirectory() as tmp, router_process(keys.site, lease_ms) as endpoint:
        scenario_file = str(pathlib.Path(tmp) / "scenario.json")
        pathlib.Path(scenario_file).write_bytes(msgspec.json.encode(scenario))
        gs = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "ground_station",
                "--connect",
                endpoint,
                "--scenario",
                scenario_file,
                "--db",
                str(pathlib.Path(tmp) / "gs.db"),
                "--link-timeout",
                str(link_timeout_s),
                "--lease-ms",
                str(lease_ms),
                "--log-level",
                "warning",
            ]
        )
        config = BusConfig(connect=(endpoint,), lease_ms=lease_ms)
        agents: dict[str, LightAgent] = {}
        try:
            with Bus.open(config) as client:
                watch = EventWatch(client, keys)
                deadline = time.monotonic() + 20
                while not client.alive(keys.all_alive(Role.GROUND_STATION)):
                    if time.monotonic() > deadline:
                        raise RuntimeError("ground station did not start")
                    time.sleep(0.05)
                for spec in scenario.fleet.uavs[:uavs]:
                    agents[spec.id] = LightAgent(config, scenario, spec.id)
                while not all(a.plans for a in agents.values()):
                    time.sleep(0.01)
                replies: list[float] = []
                preload_s = _preload(client, keys, preload, seed, replies, 120.0)
                settle(client, keys)  # the background improvement of the loaded plan
                submitted = time.perf_counter()
                latencies = sorted(
                    _event_to_plan(client, keys, agents, watch, events, seed, replies)
                )
                stability = measure_stability(
                    client, keys, watch, submitted, (uavs, events), steady_s, gs.pid
                )
                lost = _silence_to_lost(
                    endpoint, scenario_file, scenario.fleet.uavs[-1].id, lease_ms, watch
                )
                big: list[float] = []
                if big_inspect > 0:
                    request = _inspection(random.Random(seed + 7), 999_999, big_inspect)
                    _timed_submit(client, keys, request, big)
                    replies += big
                metrics = client.query(keys.rpc("metrics"), GetMetrics(), MetricsReply, 10.0)
        finally:
            for agent in agents.values():
                agent.close()
            gs.terminate()
            gs.wait(10)
    values = metrics.values
    return {
        "agents": uavs,
        "actions_preloaded": preload,
        "preload_planned_s": preload_s,
        "events": len(latencies),
        "event_to_plan_p50_ms": percentile_ms(latencies, 0.5),
        "event_to_plan_p99_ms": percentile_ms(latencies, 0.99),
        "submit_reply_p50_ms": percentile_ms(replies, 0.5),
        "submit_reply_p99_ms": percentile_ms(replies, 0.99),
        "submit_reply_big_inspect_ms": big[0] * 1e3 if big else float("nan"),
        "big_inspect_waypoints": big_inspect,
        **stability,
        "replans": values.get("replans", 0.0),
        "replans_incremental": values.get("replans_incremental", 0.0),
        "replans_rebuilt": values.get("replans_rebuilt", 0.0),
        "replan_triggers": values.get("replan_triggers", 0.0),
        "improvements_adopted": values.get("improvements_adopted", 0.0),
        "improvements_rejected": values.get("improvements_rejected", 0.0),
        "plan_objective_s": values.get("plan_objective_s", float("nan")),
        "link_timeout_s": link_timeout_s,
        **lost,
    }


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``linecrew bench ground-station``."""
    parser = argparse.ArgumentParser(
        prog="linecrew bench ground-station",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--uavs", type=int, default=20, help="light agents")
    parser.add_argument("--events", type=int, default=50, help="actions submitted")
    parser.add_argument("--link-timeout", type=float, default=5.0, help="gs_link_timeout (s)")
    parser.add_argument("--lease-ms", type=int, default=500, help="zenoh transport lease")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--steady-s", type=float, default=20.0, help="quiet time watched (s)")
    parser.add_argument("--preload", type=int, default=200, help="actions in force first")
    parser.add_argument(
        "--big-inspect", type=int, default=2000, help="waypoints of the big submit (0: none)"
    )
    parser.add_argument("--json", action="store_true", help="print JSON")
    args = parser.parse_args(argv)
    results = run(
        args.uavs,
        args.events,
        args.link_timeout,
        args.lease_ms,
        args.seed,
        args.steady_s,
        args.preload,
        args.big_inspect,
    )
    if args.json:
        print(json.dumps(results, indent=2))
    else:
        for name, value in results.items():
            print(
                f"{name:>24}  {value:.4g}" if isinstance(value, float) else f"{name:>24}  {value}"
            )
    return 0
