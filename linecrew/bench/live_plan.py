"""``linecrew bench live-plan``: how good the plan is that the live ground
station converges to, against the offline planner given the same state.

For each mission (the paper's scenario, and the paper site with N UAVs and
M random inspections), a ground station is built in process around a real
SQLite file: the UAVs report at home, the actions are submitted one by one
and planned by the planning worker exactly as live (incremental session,
then the background improvement attempts with their hysteresis, as after
the last trigger of a quiet mission). The same state is then planned offline
by ``linecrew plan --improve-ms`` (constructions, variants, local search for
that long). Printed: both objectives (weight-averaged completion + makespan,
seconds), the live plan's gap to the offline one, and what it took.
"""

from __future__ import annotations

import argparse
import json
import random
import tempfile
import time
from pathlib import Path

from ground_station import planner as pl
from ground_station.event_log import EventLog
from ground_station.fleet_monitor import FleetMonitor
from ground_station.missions import MissionManager
from ground_station.planner.api import score
from ground_station.planning import build_problem, capacity_wh, home_station
from ground_station.replan_jobs import ImproveSettings
from ground_station.replanner import Replanner
from ground_station.store import Store
from linecrew.bench.ground_station import random_inspection
from linecrew.planner_tools.cli import deadline
from linecrew_runtime.scenarios import load, with_fleet_size
from proto import FlightState, GeoPoint, Scenario, SubmitAction, Telemetry

NOW_S = 100.0
"""The mission second at which the state is planned."""


def _telemetry(scenario: Scenario, uav_id: str) -> Telemetry:
    spec = next(u for u in scenario.fleet.uavs if u.id == uav_id)
    capacity = capacity_wh(scenario.fleet, uav_id)
    return Telemetry(
        uav_id=uav_id,
        stamp_s=NOW_S,
        position=home_station(scenario.site, spec).position,
        geo=GeoPoint(),
        battery_wh=capacity,
        battery_fraction=1.0,
        flight_state=FlightState.LANDED,
    )


def live_and_offline(
    scenario: Scenario,
    requests: list[SubmitAction],
    db: str,
    offline_ms: float,
    settings: ImproveSettings,
) -> dict[str, float]:
    """Plan ``requests`` as the live gs does, then the same state offline."""
    store = Store(db)
    monitor = FleetMonitor([u.id for u in scenario.fleet.uavs], 5.0)
    events = EventLog(store, lambda _event: None, lambda: NOW_S)
    replanner = Replanner(
        scenario=scenario,
        store=store,
        monitor=monitor,
        events=events,
        send=lambda _plan: None,
        improve=settings,
    )
    manager = MissionManager(
        scenario=scenario,
        store=store,
        monitor=monitor,
        events=events,
        replanner=replanner,
        clock=lambda: NOW_S,
    )
    for spec in scenario.fleet.uavs:
        monitor.on_token(spec.id, True, NOW_S)
        monitor.on_telemetry(_telemetry(scenario, spec.id), NOW_S)
    manager.on_fleet_changes(monitor.check(NOW_S))
    started = time.perf_counter()
    for request in requests:
        manager.submit(request)
        manager.worker.settle()
    planned_s = time.perf_counter() - started
    started = time.perf_counter()
    manager.worker.settle(improve=True)
    improve_s = time.perf_counter() - started
    assert replanner.live.session is not None
    live = score(replanner.live.session.plan())
    job = replanner.prepare(manager.in_force(), NOW_S, "offline reference")
    problem = build_problem(
        scenario.site, scenario.fleet, job.uavs, job.records, NOW_S, monitor_starts=job.starts
    )
    stop, _ = deadline(offline_ms)
    offline = score(pl.plan(problem, should_stop=stop))  # type: ignore[arg-type]
    epochs = store.counter("epoch")
    store.close()
    return {
        "uavs": float(len(scenario.fleet.uavs)),
        "actions": float(len(requests)),
        "live_objective_s": live[1],
        "live_unplaced": float(live[0]),
        "offline_objective_s": offline[1],
        "offline_unplaced": float(offline[0]),
        "gap": (live[1] - offline[1]) / offline[1] if offline[1] else 0.0,
        "live_planning_s": planned_s,
        "live_improvement_s": improve_s,
        "improvements_adopted": float(replanner.stats.improvements_adopted),
        "epochs": float(epochs),
    }


def missions(sizes: list[tuple[int, int]], seed: int) -> dict[str, tuple[Scenario, list]]:
    """The paper scenario with its actions, and N x M random missions on its site."""
    paper = load("paper")
    out = {
        "paper": (
            paper,
            [SubmitAction(request_id=a.id, action=a.action, action_id=a.id) for a in paper.actions],
        )
    }
    for uavs, actions in sizes:
        rng = random.Random(seed * 7919 + uavs * 31 + actions)
        requests = [
            SubmitAction(request_id=f"q{i}", action=random_inspection(rng)) for i in range(actions)
        ]
        out[f"{uavs}x{actions}"] = (with_fleet_size(paper, uavs), requests)
    return out


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``linecrew bench live-plan``."""
    parser = argparse.ArgumentParser(
        prog="linecrew bench live-plan",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "--sizes", nargs="*", default=["10x50", "20x200"], help="UAVsxACTIONS missions"
    )
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--offline-ms", type=float, default=1000.0, help="offline budget (ms)")
    defaults = ImproveSettings()
    parser.add_argument("--rounds", type=int, default=defaults.rounds, help="rounds per attempt")
    parser.add_argument("--attempts", type=int, default=defaults.attempts, help="per state")
    parser.add_argument("--freeze-s", type=float, default=defaults.freeze_s, help="horizon")
    parser.add_argument("--json", action="store_true", help="print JSON")
    args = parser.parse_args(argv)
    settings = ImproveSettings(rounds=args.rounds, attempts=args.attempts, freeze_s=args.freeze_s)
    sizes = [tuple(int(v) for v in s.split("x")) for s in args.sizes]
    results: dict[str, dict[str, float]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name, (scenario, requests) in missions(sizes, args.seed).items():  # type: ignore[arg-type]
            db = str(Path(tmp) / f"{name}.db")
            results[name] = live_and_offline(scenario, requests, db, args.offline_ms, settings)
    if args.json:
        print(json.dumps(results, indent=2))
        return 0
    for name, values in results.items():
        print(name)
        for key, value in values.items():
            print(f"  {key:>22}  {value:.4g}")
    return 0
