"""``linecrew bench planner``: speed, replan latency and quality.

For each size (UAVs x actions) and seed it generates a corridor instance and
measures: the complete heuristic's full-plan time; single-event replan
times over a seeded stream of events (p50 / p99); and the quality
(makespan, energy, weighted completion, score = weighted completion +
makespan) of the plain paper heuristic, the complete heuristic and the
complete heuristic + improvement. Every plan is validated.

``--family`` picks instance families (``generator.FAMILIES``).
``--reference-ms`` adds best-known plans per instance (``bench_reference``:
long improvement runs from the planner and from the paper heuristic and,
with ``--reference cpsat``, OR-Tools CP-SAT seeded from each, on instances
small enough for it; the optional ``bench`` extra). Gaps are measured
against the best plan seen, per instance and as mean / worst.
"""

from __future__ import annotations

import argparse
import random
import statistics
import time
from collections.abc import Callable
from typing import Any

import msgspec

from ground_station.planner.api import plan, score
from ground_station.planner.model import DeliverJob, MonitorJob, Problem
from ground_station.planner.replan import (
    ActionAdded,
    ActionCancelled,
    ActionChanged,
    BatteryLow,
    Event,
    Session,
    TaskFinished,
    UavBack,
    UavLost,
)
from ground_station.planner.result import Solution
from ground_station.planner.routes import Options
from ground_station.planner.validate import validate
from linecrew.planner_tools.bench_reference import best_known, deadline, references
from linecrew.planner_tools.generator import FAMILIES, generate, ring_bearing

DEFAULT_SIZES = ("3x4", "5x20", "10x50", "20x200", "50x500")


def calibration_ms() -> float:
    """CPU speed yardstick: ms for a fixed pure-Python loop; divide timings by
    it to compare runs made on differently loaded machines."""
    t0 = time.perf_counter()
    x = 0
    for i in range(2_000_000):
        x += i & 7
    return (time.perf_counter() - t0) * 1000.0


def _timed(fn: Callable[[], Solution]) -> tuple[Solution, float]:
    t0 = time.perf_counter()
    out = fn()
    return out, (time.perf_counter() - t0) * 1000.0


def _quality(p: Solution) -> dict[str, float]:
    m = p.metrics
    return {
        "score": score(p)[1],
        "makespan_s": m.makespan_s,
        "energy_wh": m.energy_wh,
        "weighted_completion_s": m.weighted_completion_s,
        "unplaced": float(len(p.unplaced)),
    }


def tool_stations(problem: Problem) -> set[str]:
    return {t.id for t in problem.tool_stations}


def _next_event(s: Session, rng: random.Random, pool: list, n: int) -> Event | None:
    problem = s.problem
    kind = rng.choice(("add", "add", "cancel", "change", "lost", "back", "battery", "finished"))
    lost = [u for u in problem.uavs if not u.available]
    live = sorted(s.ctx.routes)
    if kind == "add" or not problem.actions:
        a = pool[n % len(pool)]
        if isinstance(a, DeliverJob) and a.tool_station not in tool_stations(problem):
            a = msgspec.structs.replace(a, tool_station=problem.tool_stations[0].id)
        if isinstance(a, MonitorJob):
            bearing = ring_bearing(problem.actions, a.worker_m, a.k)
            a = msgspec.structs.replace(a, bearing_deg=bearing)
        return ActionAdded(action=msgspec.structs.replace(a, id=f"ev{n}"))
    if kind == "cancel":
        return ActionCancelled(action_id=rng.choice(problem.actions).id)
    if kind == "change":
        a = rng.choice(problem.actions)
        return ActionChanged(action=msgspec.structs.replace(a, weight=float(rng.randint(1, 5))))
    if kind == "back" and lost:
        return UavBack(uav=rng.choice(lost))
    if not live:
        return None
    uid = rng.choice(live)
    if kind in ("lost", "back"):
        return UavLost(uav_id=uid) if len(live) > 2 else None
    r = s.ctx.routes[uid]
    if kind == "battery":
        return BatteryLow(uav_id=uid, energy_wh=max(0.0, r.init.e * 0.6))
    if r.tasks and r.tasks[0].kind in ("inspect", "deliver"):
        return TaskFinished(uav_id=uid, position_m=r.tasks[0].pos, energy_wh=r.states[0].e)
    return None


def replan_times(
    problem: Problem, m: int, events: int, seed: int, repeat: int = 1
) -> tuple[list[float], int]:
    """Per-event replan times (ms, the minimum over ``repeat`` identical
    streams, to filter out machine noise) and validator violations."""
    best: list[float] = []
    violations = 0
    for r in range(max(1, repeat)):
        times, v = _replan_stream(problem, m, events, seed, validate_plans=(r == 0))
        best = times if not best else [min(a, b) for a, b in zip(best, times, strict=True)]
        violations += v
    return best, violations


def _replan_stream(
    problem: Problem, m: int, events: int, seed: int, validate_plans: bool
) -> tuple[list[float], int]:
    """Per-event replan times (ms) and validator violations over a stream.

    New actions come from another instance of the same size (same station
    and tool-station ids)."""
    s = Session(problem)
    pool = list(generate(len(problem.uavs), m, seed + 7919).actions)
    rng = random.Random(seed)
    times: list[float] = []
    violations = 0
    n = 0
    while len(times) < events and n < events * 4:
        n += 1
        ev = _next_event(s, rng, pool, n)
        if ev is None:
            continue
        t0 = time.perf_counter()
        p = s.apply(ev)
        times.append((time.perf_counter() - t0) * 1000.0)
        if validate_plans:
            violations += len(validate(s.problem, p))
    return times, violations


def _pct(xs: list[float], q: float) -> float:
    if not xs:
        return 0.0
    xs = sorted(xs)
    return xs[min(len(xs) - 1, round(q * (len(xs) - 1)))]


def run_case(family: str, n: int, m: int, seed: int, args: argparse.Namespace) -> dict[str, Any]:
    problem = generate(n, m, seed, family)
    calib = calibration_ms()
    paper, paper_ms = _timed(lambda: plan(problem, Options(mode="paper")))
    complete, plan_ms = _timed(lambda: plan(problem))
    for _ in range(args.repeat - 1):  # minimum over repeats filters machine noise
        plan_ms = min(plan_ms, _timed(lambda: plan(problem))[1])
    improved, improved_ms = _timed(lambda: plan(problem, should_stop=deadline(args.improve_ms)))
    violations = sum(len(validate(problem, p)) for p in (paper, complete, improved))
    times, rv = replan_times(problem, m, args.events, seed, args.repeat)
    row: dict[str, Any] = {
        "family": family,
        "size": f"{n}x{m}",
        "seed": seed,
        "calibration_ms": calib,
        "plan_ms": plan_ms,
        "paper_ms": paper_ms,
        "improved_ms": improved_ms,
        "replan_p50_ms": _pct(times, 0.5),
        "replan_p99_ms": _pct(times, 0.99),
        "replan_events": len(times),
        "violations": violations + rv,
        "paper": _quality(paper),
        "complete": _quality(complete),
        "improved": _quality(improved),
    }
    if args.reference_ms > 0:
        plans, info = references(
            problem, improved, paper, args.reference_ms, args.reference == "cpsat"
        )
        best = best_known(plans, info)
        row["violations"] += sum(len(validate(problem, p)) for p in plans.values())
        row["references"] = {k: _quality(p) for k, p in plans.items()}
        row["cpsat"] = info
        row["reference"] = _quality(best.pop("plan"))
        row["reference_kind"], row["optimum"] = best["kind"], best["optimum"]
        row["proven"] = best["optimum"] is not None
        row["bound"] = best["bound"]
    return row


def _gap(row: dict[str, Any], key: str) -> float:
    """``key``'s score above the best plan seen for the instance (%)."""
    seen = [row[k] for k in ("paper", "complete", "improved", "reference") if k in row]
    best = min(seen, key=lambda q: (q["unplaced"], q["score"]))["score"]
    return (row[key]["score"] / best - 1.0) * 100.0 if best > 0 else 0.0


def summarise(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    out = []
    for family, size in dict.fromkeys((r["family"], r["size"]) for r in rows):
        rs = [r for r in rows if (r["family"], r["size"]) == (family, size)]
        out.append(
            {
                "family": family,
                "size": size,
                "seeds": len(rs),
                "plan_ms_median": statistics.median(r["plan_ms"] for r in rs),
                "plan_ms_at_yardstick_100": statistics.median(
                    r["plan_ms"] * 100.0 / r["calibration_ms"] for r in rs
                ),
                "plan_ms_max": max(r["plan_ms"] for r in rs),
                "replan_p50_ms": statistics.median(r["replan_p50_ms"] for r in rs),
                "replan_p99_ms": max(r["replan_p99_ms"] for r in rs),
                "violations": sum(r["violations"] for r in rs),
                "gap_paper_pct": statistics.mean(_gap(r, "paper") for r in rs),
                "gap_complete_pct": statistics.mean(_gap(r, "complete") for r in rs),
                "gap_improved_pct": statistics.mean(_gap(r, "improved") for r in rs),
                "gap_improved_worst_pct": max(_gap(r, "improved") for r in rs),
                "unplaced_improved": sum(r["improved"]["unplaced"] for r in rs),
                "reference_kinds": sorted({r.get("reference_kind", "-") for r in rs}),
                "proven": sum(bool(r.get("proven")) for r in rs),
                "gap_to_optimum_pct": [
                    (r["improved"]["score"] / r["optimum"] - 1.0) * 100.0
                    for r in rs
                    if r.get("optimum")
                ],
                "improved_not_worse_than_paper": all(
                    (r["improved"]["unplaced"], r["improved"]["score"])
                    <= (r["paper"]["unplaced"], r["paper"]["score"])
                    for r in rs
                ),
            }
        )
    return out


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="linecrew bench planner", description=__doc__)
    parser.add_argument("target", nargs="?", default="planner", choices=("planner",))
    parser.add_argument("--sizes", nargs="+", default=list(DEFAULT_SIZES), help="UAVSxACTIONS")
    parser.add_argument("--seeds", nargs="+", type=int, default=[0, 1, 2])
    parser.add_argument(
        "--family", nargs="+", default=["corridor"], choices=sorted(FAMILIES), help="instances"
    )
    parser.add_argument("--improve-ms", type=float, default=1000.0)
    parser.add_argument("--events", type=int, default=100, help="replan events per instance")
    parser.add_argument(
        "--repeat", type=int, default=3, help="timing repeats (the minimum is reported)"
    )
    parser.add_argument(
        "--reference-ms", type=float, default=0.0, help="budget of each reference per instance"
    )
    parser.add_argument(
        "--reference",
        choices=("search", "cpsat"),
        default="search",
        help="best-known by long searches, or also by OR-Tools CP-SAT (small instances)",
    )
    parser.add_argument("--json", action="store_true", help="print JSON instead of tables")
    args = parser.parse_args(argv)
    try:
        sizes = [tuple(int(x) for x in s.lower().split("x")) for s in args.sizes]
    except ValueError:
        parser.error("sizes look like 20x200")
    if args.reference == "cpsat":
        try:
            import ortools  # noqa: F401
        except ImportError:
            parser.error("--reference cpsat needs OR-Tools: pip install 'linecrew[bench]'")
    calib = calibration_ms()
    rows = [
        run_case(f, n, m, seed, args) for f in args.family for n, m in sizes for seed in args.seeds
    ]
    summary = summarise(rows)
    ok = all(s["violations"] == 0 for s in summary)
    if args.json:
        doc = {"calibration_ms": calib, "summary": summary, "runs": rows}
        print(msgspec.json.format(msgspec.json.encode(doc)).decode())
        return 0 if ok else 1
    _print_tables(rows, summary, calib, args.reference_ms > 0)
    return 0 if ok else 1


SUMMARY_COLS = (
    ("family", "family", "{}"),
    ("size", "size", "{}"),
    ("plan", "plan_ms_median", "{:.0f}"),
    ("max", "plan_ms_max", "{:.0f}"),
    ("@100", "plan_ms_at_yardstick_100", "{:.0f}"),
    ("rp50", "replan_p50_ms", "{:.1f}"),
    ("rp99", "replan_p99_ms", "{:.1f}"),
    ("paper%", "gap_paper_pct", "{:.1f}"),
    ("cmpl%", "gap_complete_pct", "{:.1f}"),
    ("impr%", "gap_improved_pct", "{:.1f}"),
    ("worst%", "gap_improved_worst_pct", "{:.1f}"),
    ("unpl", "unplaced_improved", "{:.0f}"),
    ("reference", "reference_kinds", "{}"),
    ("proven", "proven", "{}"),
    ("viol", "violations", "{}"),
)


def _instance_row(r: dict[str, Any]) -> tuple[str, ...]:
    proven = r["proven"]
    ref_gap = _gap(r, "reference")
    return (
        r["family"],
        r["size"],
        str(r["seed"]),
        f"{_gap(r, 'paper'):.1f}",
        f"{_gap(r, 'improved'):.1f}",
        f"{ref_gap:.1f}",
        r["reference_kind"],
        "proven" if proven else "best-known",
        f"{(r['improved']['score'] / r['optimum'] - 1) * 100:.1f}" if proven else "",
        f"{r['bound']:.0f}" if r["bound"] else "",
    )


def _print_tables(
    rows: list[dict[str, Any]], summary: list[dict[str, Any]], calib: float, refs: bool
) -> None:
    from rich.console import Console
    from rich.table import Table

    console = Console()
    if not console.is_terminal:
        console.width = max(console.width, 160)
    if refs:
        per = Table(title="per instance")
        per.caption = (
            "paper/impr/ref%: score above the best plan seen (impr: after --improve-ms); "
            "reference: the best reference (search, paper-search, cpsat-planner, "
            "cpsat-paper); proven: CP-SAT proved the optimum of its (restricted) model; "
            "vs opt%: planner above that optimum (negative: the planner found a plan "
            "outside the model); bound: CP-SAT lower bound on the score"
        )
        for title in (
            "family",
            "size",
            "seed",
            "paper%",
            "impr%",
            "ref%",
            "reference",
            "kind",
            "vs opt%",
            "bound",
        ):
            per.add_column(title, justify="right")
        for r in rows:
            per.add_row(*_instance_row(r))
        console.print(per)
    table = Table(title="linecrew planner bench")
    table.caption = (
        "plan/max: full plan ms (median/max over seeds); @100: plan ms scaled to a "
        "100 ms yardstick; rp50/rp99: one-event replan ms; paper/cmpl/impr%: score "
        "above the best plan seen, mean (worst: worst seed); unpl: unplaced parts after "
        "improvement; proven: seeds with a CP-SAT optimum; viol: validator violations"
    )
    for title, _, _ in SUMMARY_COLS:
        table.add_column(title, justify="right")
    for s in summary:
        table.add_row(*(_cell(s[key], fmt) for _, key, fmt in SUMMARY_COLS))
    console.print(table)
    console.print(f"CPU yardstick (fixed 2M-step Python loop): {calib:.0f} ms")
    if not refs:
        console.print("reference: none (use --reference-ms, and --reference cpsat, for best-known)")


def _cell(value: Any, fmt: str) -> str:
    return ",".join(value) if isinstance(value, list) else fmt.format(value)
