"""``linecrew bench fleet``: the whole stack (:class:`LocalRun`: router,
ground station, gateway, simulator, agents) at x1 with N simulated UAVs,
for each N of ``--uavs``, the agents hosted ``--agents-per-process`` to a
process.

- start-up: from starting the run until every agent's liveliness token is up;
- CPU % (of one core) and RSS per process kind over ``--duration`` idle
  seconds, once every agent reports ready (the agents also per UAV);
- false lost: ``uav_lost`` events in the ground station's log (nothing is
  faulted or killed during the bench);
- submit: ``--submits`` inspections POSTed to ``/v1/actions`` one at a time,
  the reply time p50 / p99 / max and the count of 5xx replies;
- event -> plan at agents: from sending a POST until every UAV whose plan
  that submit's replan changed (``plan_changed`` events of the first
  ``replan`` epoch after the POST) reports that epoch or a newer one in its
  status (an agent ticks at once on a new plan and publishes its status on
  change after that tick). p50 / p99 / max over the submits that changed a
  plan. "plan on bus" is the part until the last of those plans reached a
  subscriber beside the agents (the ground station's share).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import pathlib
import random
import sys
import tempfile
import threading
import time

import msgspec

from linecrew.bench.ground_station import random_inspection
from linecrew.launch.local_run import LocalRun, RunOptions
from linecrew.launch.proc_stats import KINDS, measure
from linecrew.launch.supervisor import StartError
from linecrew_runtime.latency import summary_ms
from linecrew_runtime.logs import configure_logging
from linecrew_runtime.scenarios import load, with_fleet_size
from proto import AgentStatus, EventKind, GetHistory, GsEvent, HistoryReply, Plan, UavTopic
from proto.errors import LinecrewError

READY_TIMEOUT_S = 120.0
PLAN_TIMEOUT_S = 10.0


class NotReady(LinecrewError, RuntimeError):
    """Agents that never reported ready."""

    code = "fleet_not_ready"


class FleetWatch:
    """The ground station's events and the agents' statuses, as they arrive."""

    def __init__(self, run: LocalRun) -> None:
        assert run.bus is not None
        self.events: list[tuple[float, GsEvent]] = []
        self.epochs: dict[str, list[tuple[float, int]]] = {}  # UAV -> (arrival, status epoch)
        self.plans: dict[str, list[tuple[float, int]]] = {}  # UAV -> (arrival, plan epoch)
        self.ready: dict[str, bool] = {}
        self._cond = threading.Condition()
        run.bus.subscribe(run.keys.events(), GsEvent, self._on_event)
        run.bus.subscribe(run.keys.all_uavs(UavTopic.STATUS), AgentStatus, self._on_status)
        run.bus.subscribe(run.keys.all_uavs(UavTopic.PLAN), Plan, self._on_plan)

    def _on_event(self, _key: str, event: GsEvent) -> None:
        with self._cond:
            self.events.append((time.perf_counter(), event))
            self._cond.notify_all()

    def _on_status(self, _key: str, status: AgentStatus) -> None:
        with self._cond:
            self.ready[status.uav_id] = status.ready
            seen = self.epochs.setdefault(status.uav_id, [])
            if not seen or seen[-1][1] != status.epoch:
                seen.append((time.perf_counter(), status.epoch))
            self._cond.notify_all()

    def _on_plan(self, _key: str, plan: Plan) -> None:
        with self._cond:
            self.plans.setdefault(plan.uav_id, []).append((time.perf_counter(), plan.epoch))
            self._cond.notify_all()

    def wait(self, predicate: object, timeout_s: float) -> object:
        """The first truthy ``predicate()`` (called under the lock), or None."""
        deadline = time.monotonic() + timeout_s
        with self._cond:
            while not (found := predicate()):  # type: ignore[operator]
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    return None
                self._cond.wait(remaining)
            return found

    def all_ready(self, uavs: list[str]) -> bool:
        return all(self.ready.get(u) for u in uavs)

    def plan_arrived(self, since: float) -> tuple[float, float] | None:
        """When the plans of the first replan after ``since`` were on the bus
        and when every UAV they changed showed their epoch (None until then)."""
        epoch = next(
            (e.epoch for t, e in self.events if t >= since and e.kind == EventKind.REPLAN), None
        )
        if epoch is None:
            return None
        changes = (e for _, e in self.events if e.kind == EventKind.PLAN_CHANGED)
        changed = {e.uav_id for e in changes if e.epoch == epoch and e.uav_id}
        sent = [_reached(self.plans.get(uav, []), epoch, since) for uav in changed]
        shown = [_reached(self.epochs.get(uav, []), epoch, since) for uav in changed]
        if not changed or None in sent or None in shown:
            return None
        return max(t for t in sent if t), max(t for t in shown if t)


def _reached(series: list[tuple[float, int]], epoch: int, since: float) -> float | None:
    """The first time after ``since`` that ``series`` reached ``epoch``."""
    return next((t for t, e in series if t >= since and e >= epoch), None)


def _submits(run: LocalRun, watch: FleetWatch, count: int, seed: int) -> dict[str, object]:
    """POST ``count`` inspections one at a time, each after the last one's plan."""
    rng = random.Random(seed)
    replies, on_bus, plans, errors = [], [], [], 0
    with run.http(timeout_s=30.0) as http:
        for _ in range(count):
            body = msgspec.to_builtins(random_inspection(rng))
            sent = time.perf_counter()
            response = http.post("/v1/actions", json=body)
            replies.append(time.perf_counter() - sent)
            errors += response.status_code >= 500
            arrived = watch.wait(lambda s=sent: watch.plan_arrived(s), PLAN_TIMEOUT_S)
            if isinstance(arrived, tuple):
                on_bus.append(arrived[0] - sent)
                plans.append(arrived[1] - sent)
    return {
        "submits": count,
        "submit_5xx": errors,
        "submit": summary_ms(replies),
        "event_to_plan": {"n": len(plans), **summary_ms(plans)},
        "event_to_plan_on_bus": summary_ms(on_bus),
    }


def _lost_count(run: LocalRun) -> int:
    """``uav_lost`` events in the whole ground-station log."""
    assert run.bus is not None
    lost, after = 0, 0
    while True:
        reply = run.bus.query(
            run.keys.rpc("history"), GetHistory(after_seq=after, limit=5000), HistoryReply, 10.0
        )
        if not reply.events:
            return lost
        lost += sum(e.kind == EventKind.UAV_LOST for e in reply.events)
        after = reply.events[-1].seq


def bench_size(uavs: int, args: argparse.Namespace, run_dir: pathlib.Path) -> dict[str, object]:
    """One fleet size, start to stop."""
    scenario = with_fleet_size(load(args.scenario), uavs)
    ids = [u.id for u in scenario.fleet.uavs]
    options = RunOptions(
        run_dir=run_dir, register=False, agents_per_process=args.agents_per_process
    )
    load_before = os.getloadavg()[0]
    started = time.perf_counter()
    with LocalRun(scenario, options) as run:
        start_s = time.perf_counter() - started
        watch = FleetWatch(run)
        if not watch.wait(lambda: watch.all_ready(ids), READY_TIMEOUT_S):
            not_ready = sorted(u for u in ids if not watch.ready.get(u))
            raise NotReady(f"agents not ready after {READY_TIMEOUT_S:.0f} s: {not_ready}")
        usage = measure(run.supervisor.children, args.duration)
        latencies = _submits(run, watch, args.submits, args.seed)
        lost = _lost_count(run)
    agents = usage["agents"]
    return {
        "uavs": uavs,
        "agent_processes": agents.procs,
        "start_s": start_s,
        "cpu_pct": {kind: u.cpu_pct for kind, u in usage.items()},
        "rss_mb": {kind: u.rss_mb for kind, u in usage.items()},
        "agent_cpu_pct_per_uav": agents.cpu_pct / uavs,
        "agent_rss_mb_per_uav": agents.rss_mb / uavs,
        "false_lost": lost,
        **latencies,
        "load_1min": {"before": load_before, "after": os.getloadavg()[0]},
    }


def _rows(result: dict) -> list[tuple[str, object]]:
    """(metric, value) pairs of one size, in table order."""
    submit, plan, bus = result["submit"], result["event_to_plan"], result["event_to_plan_on_bus"]
    return [
        ("agent processes", result["agent_processes"]),
        ("start-up s", result["start_s"]),
        *((f"cpu % {kind}", result["cpu_pct"][kind]) for kind in KINDS),
        ("cpu % total", sum(result["cpu_pct"].values())),
        *((f"rss MB {kind}", result["rss_mb"][kind]) for kind in KINDS),
        ("agent cpu %/UAV", result["agent_cpu_pct_per_uav"]),
        ("agent rss MB/UAV", result["agent_rss_mb_per_uav"]),
        ("false lost", result["false_lost"]),
        ("submits", result["submits"]),
        ("submit 5xx", result["submit_5xx"]),
        *((f"submit {k[:-3]} ms", submit[k]) for k in ("p50_ms", "p99_ms", "max_ms")),
        ("event->plan n", plan["n"]),
        *((f"event->plan {k[:-3]} ms", plan[k]) for k in ("p50_ms", "p99_ms", "max_ms")),
        *((f"  plan on bus {k[:-3]} ms", bus[k]) for k in ("p50_ms", "p99_ms")),
        ("load 1 min", result["load_1min"]["after"]),
    ]


def _cell(value: object) -> str:
    if value is None:
        return "-"
    return f"{value:.1f}" if isinstance(value, float) else str(value)


def table(results: list[dict]) -> str:
    """A metric per row, a fleet size per column."""
    columns = [[(name, _cell(v)) for name, v in _rows(r)] for r in results]
    header = ["UAVs", *(str(r["uavs"]) for r in results)]
    lines = [[name, *(col[i][1] for col in columns)] for i, (name, _) in enumerate(columns[0])]
    widths = [max(len(row[i]) for row in [header, *lines]) for i in range(len(header))]
    return "\n".join(
        "  ".join(
            cell.ljust(widths[0]) if i == 0 else cell.rjust(widths[i]) for i, cell in enumerate(row)
        )
        for row in [header, *lines]
    )


def parser() -> argparse.ArgumentParser:
    """The flags of ``linecrew bench fleet``."""
    p = argparse.ArgumentParser(
        prog="linecrew bench fleet",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--uavs", type=int, nargs="+", default=[10, 20, 50, 100], help="fleet sizes")
    p.add_argument(
        "--agents-per-process",
        type=int,
        default=25,
        metavar="N",
        help="agents per host (1: a process each)",
    )
    p.add_argument("--duration", type=float, default=20.0, help="idle window measured (s)")
    p.add_argument("--submits", type=int, default=60, help="inspections submitted per size")
    p.add_argument("--scenario", default="paper", help="the scenario resized to each N")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--run-dir", type=pathlib.Path, help="keep each size's logs in DIR/uavs-N")
    p.add_argument("--json", action="store_true", help="print JSON")
    return p


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``linecrew bench fleet``."""
    args = parser().parse_args(argv)
    if args.agents_per_process < 1 or args.duration <= 0 or args.submits < 0:
        parser().error("--agents-per-process >= 1, --duration > 0, --submits >= 0")
    configure_logging("warning", "plain", "bench")
    results = []
    with contextlib.ExitStack() as stack:
        root = args.run_dir or pathlib.Path(
            stack.enter_context(tempfile.TemporaryDirectory(prefix="bench-fleet-"))
        )
        try:
            for uavs in args.uavs:
                results.append(bench_size(uavs, args, root / f"uavs-{uavs}"))
        except (StartError, NotReady) as exc:
            print(f"linecrew bench fleet: {exc}", file=sys.stderr)
            return 1
    print(json.dumps(results, indent=2) if args.json else table(results))
    return 0
