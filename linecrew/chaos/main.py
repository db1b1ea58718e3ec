"""``linecrew chaos --seed S --duration T [--netns]``: start a local fleet,
inject a seeded random mix (partitions of random length and bursts of short
cuts, process kills, a router kill during a replan, faults, new actions),
check the invariants continuously, print a report. Partitions freeze the
process on loopback; with ``--netns`` every process runs in a network
namespace of its own and a partition cuts its Zenoh link for real (needs
root: ``ip netns add``). Exit 0 if no invariant broke, 1 on a violation, 2
if the fleet did not start. The same seed gives the same schedule
(``--schedule-only`` prints it)."""

from __future__ import annotations

import argparse
import pathlib
import sys

from linecrew.chaos.netns import NetnsError, check_available
from linecrew.chaos.report import render
from linecrew.chaos.runner import ChaosOptions, ChaosRunner
from linecrew.chaos.schedule import make_schedule
from linecrew.launch.supervisor import StartError
from linecrew_runtime.logs import configure_logging
from linecrew_runtime.process import Shutdown
from linecrew_runtime.scenarios import ScenarioError, load


def main(argv: list[str] | None = None) -> int:
    """Run one chaos run; see the module docstring for the exit codes."""
    parser = argparse.ArgumentParser(
        prog="linecrew chaos",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--seed", type=int, required=True, help="drives every choice and time")
    parser.add_argument("--duration", type=float, default=60.0, help="wall s of injections")
    parser.add_argument("--drain", type=float, default=150.0, help="wall s for actions to end")
    parser.add_argument("--speedup", type=float, default=10.0, help="mission s per wall s")
    parser.add_argument("--scenario", default="paper", help="scenario file or built-in name")
    parser.add_argument("--run-dir", type=pathlib.Path, help="logs and store (runs/<time>)")
    parser.add_argument(
        "--no-scenario-actions", action="store_true", help="only the chaos schedule's actions"
    )
    parser.add_argument(
        "--netns", action="store_true", help="real cuts: each process in its own network namespace"
    )
    parser.add_argument("--schedule-only", action="store_true", help="print the schedule, exit")
    parser.add_argument("--log-level", default="warning")
    args = parser.parse_args(argv)
    configure_logging(args.log_level, "plain", "chaos")
    try:
        scenario = load(args.scenario)
    except ScenarioError as exc:
        print(f"linecrew chaos: {exc}", file=sys.stderr)
        return 2
    if args.schedule_only:
        for injection in make_schedule(args.seed, args.duration, scenario, args.netns):
            print(f"{injection.at_s:6.1f}  {injection.describe()}")
        return 0
    options = ChaosOptions(
        seed=args.seed,
        duration_s=args.duration,
        drain_s=args.drain,
        speedup=args.speedup,
        run_dir=args.run_dir,
        scenario_actions=not args.no_scenario_actions,
        netns=args.netns,
    )
    try:
        if args.netns:
            check_available()  # refused before anything starts
        result = ChaosRunner(scenario, options, Shutdown().install()).run()
    except NetnsError as exc:
        print(f"linecrew chaos: --netns: {exc}", file=sys.stderr)
        return 2
    except StartError as exc:
        print(f"linecrew chaos: {exc}", file=sys.stderr)
        return 2
    print(render(result))
    return 0 if result.ok else 1


if __name__ == "__main__":
    sys.exit(main())
