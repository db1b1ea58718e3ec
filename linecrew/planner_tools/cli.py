"""Command-line front ends: ``linecrew plan`` and ``linecrew bench planner``.

The only planner modules that touch files, clocks or the terminal.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import msgspec
import yaml
from rich.console import Console
from rich.table import Table

from ground_station.planner.api import plan
from ground_station.planner.errors import PlanningProblemError
from ground_station.planner.load import plan_from_json, problem_from_json, problem_from_obj
from ground_station.planner.metrics import compute_metrics
from ground_station.planner.model import Problem
from ground_station.planner.result import Solution
from ground_station.planner.routes import Options
from ground_station.planner.validate import validate
from linecrew.planner_tools.gantt import gantt, unplaced_table


def read_problem(path: str) -> Problem:
    """Load a problem from a .json or .yaml/.yml file."""
    data = Path(path).read_bytes()
    if path.endswith((".yaml", ".yml")):
        try:
            obj = yaml.safe_load(data)
        except yaml.YAMLError as err:
            raise PlanningProblemError("$", f"not valid YAML: {err}") from None
        return problem_from_obj(obj)
    return problem_from_json(data)


def deadline(ms: float) -> tuple[object, float]:
    end = time.perf_counter() + ms / 1000.0
    return (lambda: time.perf_counter() >= end), end


def metrics_table(p: Solution) -> Table:
    m = p.metrics
    table = Table(title="Metrics")
    table.add_column("metric")
    table.add_column("value", justify="right")
    for name, value in (
        ("makespan", f"{m.makespan_s:.1f} s"),
        ("weighted completion", f"{m.weighted_completion_s:.1f} s"),
        ("distance", f"{m.distance_m:.1f} m"),
        ("energy", f"{m.energy_wh:.1f} Wh"),
        ("recharges", str(m.recharges)),
        ("unplaced parts", str(m.unplaced_parts)),
        ("planning time", f"{m.planning_time_s * 1000:.1f} ms"),
    ):
        table.add_row(name, value)
    return table


def plan_main(argv: list[str]) -> int:
    """``linecrew plan PROBLEM [-o PLAN.json] [--improve-ms N]`` and
    ``linecrew plan --validate PROBLEM PLAN``. Exit 0 ok, 1 invalid plan,
    2 bad input."""
    parser = argparse.ArgumentParser(prog="linecrew plan", description=plan_main.__doc__)
    parser.add_argument("problem", help="planning problem (.json, .yaml)")
    parser.add_argument("plan", nargs="?", help="plan to check (with --validate)")
    parser.add_argument("--validate", action="store_true", help="validate PLAN against PROBLEM")
    parser.add_argument("-o", "--output", help="write the plan as JSON here")
    parser.add_argument(
        "--improve-ms", type=float, default=200.0, help="improvement budget in ms (0: none)"
    )
    parser.add_argument("--mode", choices=("complete", "paper"), default="complete")
    args = parser.parse_args(argv)
    console = Console()
    err = Console(stderr=True)
    try:
        problem = read_problem(args.problem)
        if args.validate:
            if not args.plan:
                parser.error("--validate needs PROBLEM and PLAN")
            candidate = plan_from_json(Path(args.plan).read_bytes())
            violations = validate(problem, candidate)
            for v in violations:
                who = " ".join(x for x in (v.uav_id, v.action_id) if x)
                console.print(f"[red]{v.code}[/red] {who}: {v.detail}")
            if violations:
                console.print(f"{len(violations)} violation(s)")
                return 1
            console.print("[green]plan is valid[/green]")
            return 0
    except (OSError, PlanningProblemError) as exc:
        err.print(f"error: {exc}")
        return 2
    t0 = time.perf_counter()
    stop = None
    if args.improve_ms > 0:
        stop, _ = deadline(args.improve_ms)
    result = plan(problem, Options(mode=args.mode), should_stop=stop)  # type: ignore[arg-type]
    elapsed = time.perf_counter() - t0
    result = msgspec.structs.replace(
        result, metrics=compute_metrics(problem, result, planning_time_s=elapsed)
    )
    console.print(gantt(result, problem.now_s, width=max(20, console.width - 24)))
    if result.unplaced:
        console.print(unplaced_table(result.unplaced))
    console.print(metrics_table(result))
    violations = validate(problem, result)
    if violations:  # a planner bug: say so loudly
        err.print(f"[red]BUG: {len(violations)} validator violation(s)[/red]")
        return 1
    if args.output:
        Path(args.output).write_bytes(msgspec.json.format(msgspec.json.encode(result)) + b"\n")
        console.print(f"plan written to {args.output}")
    return 0


def bench_main(argv: list[str]) -> int:
    """``linecrew bench planner [--sizes ...] [--seeds ...] [--json]``."""
    from linecrew.planner_tools import bench

    return bench.main(argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(plan_main(sys.argv[1:]))
