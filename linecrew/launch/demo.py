"""``linecrew demo``: the paper's scenario end to end.

Starts everything (as ``linecrew up``), says what runs and what the scenario
asks, submits the scripted actions at their times through the REST gateway,
tells the ground station's events in plain words above a live progress bar
per action, and ends with the executed timeline, a summary and the run
report (``RUN_DIR/report.html``, see :mod:`linecrew.report`). Exit code 0
only if every action completed.
"""

from __future__ import annotations

import argparse
import pathlib
import sys
import time
from collections.abc import Callable

import msgspec
from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn
from rich.table import Table

from linecrew.client.gateway import Gateway, GatewayError
from linecrew.client.render import timeline
from linecrew.launch.local_run import LocalRun
from linecrew.launch.narrate import Narrator, intro, outcome_text
from linecrew.launch.recorder import ExecutionRecorder
from linecrew.launch.secure import SecureProfileError
from linecrew.launch.supervisor import StartError
from linecrew.launch.up import add_run_arguments, options_from, scenario_from
from linecrew_runtime.logs import configure_logging
from linecrew_runtime.process import Shutdown
from linecrew_runtime.scenarios import ScenarioError
from proto import GetSimState, GsEvent, SimState
from proto.scenario import Scenario

TERMINAL = {"completed", "failed", "cancelled"}
HELP = """\
The paper's scenario (or --scenario FILE) end to end: starts everything as
linecrew up does, says what runs and what the scenario asks, submits the
scripted actions at their times through the REST gateway, tells the ground
station's events in plain words above a progress bar per action, and ends
with the executed timeline, a summary and the run report (an HTML page in
the run directory, its path printed last). Exit code 0 only if every action
completed.
"""


def run_mission(
    gateway: Gateway,
    scenario: Scenario,
    speedup: float,
    timeout_s: float,
    shutdown: Shutdown,
    console: Console,
    on_tick: Callable[[float, list[dict]], None] | None = None,
    narrator: Narrator | None = None,
) -> tuple[list[dict], ExecutionRecorder]:
    """Submit the scripted actions on time and follow them until all end.
    ``on_tick(mission_s_since_start, records)`` runs every half second (tests
    inject faults there). With a ``narrator`` (its inbox fed by the event
    subscription), its lines are printed above the progress bars."""
    recorder = ExecutionRecorder()
    pending = sorted(scenario.actions, key=lambda a: a.at_s)
    started = time.monotonic()
    records: list[dict] = []
    with Progress(
        TextColumn("{task.description:<28}"),
        BarColumn(),
        TextColumn("{task.fields[state]:<12}"),
        console=console,
    ) as progress:

        def tell(events: list[GsEvent], plans: list[dict]) -> None:
            if narrator is not None:
                for line in narrator.lines(events, plans):
                    progress.console.print(line, markup=False, highlight=False)

        bars = {a.id: progress.add_task(a.id, total=1.0, state="waiting") for a in pending}
        while not shutdown.is_set() and time.monotonic() - started < timeout_s:
            elapsed_mission_s = (time.monotonic() - started) * speedup
            while pending and pending[0].at_s <= elapsed_mission_s:
                scripted = pending.pop(0)
                body = {
                    **msgspec.to_builtins(scripted.action),
                    "action_id": scripted.id,
                    "request_id": f"demo-{scripted.id}",
                }
                gateway.call("POST", "/v1/actions", json=body)
            events = narrator.drain() if narrator else []  # before the plans: those are newer
            records = gateway.call("GET", "/v1/actions")
            now = time.time() * speedup
            plans = gateway.call("GET", "/v1/plan")
            recorder.plans(plans)
            recorder.fleet(gateway.call("GET", "/v1/fleet"), now)
            tell(events, plans)
            for record in records:
                if record["action_id"] in bars:
                    progress.update(
                        bars[record["action_id"]],
                        completed=record["progress"],
                        state=record["state"],
                    )
            if on_tick is not None:
                on_tick(elapsed_mission_s, records)
            if not pending and records and all(r["state"] in TERMINAL for r in records):
                break
            shutdown.wait(0.5)
        if narrator is not None:  # the events behind the last records
            shutdown.wait(0.3)
            tell(narrator.drain(), gateway.call("GET", "/v1/plan"))
    recorder.finish(time.time() * speedup)
    return records, recorder


def summary(
    records: list[dict], recorder: ExecutionRecorder, truth: SimState | None, handovers: int
) -> Table:
    """Each action's outcome and what the fleet did."""
    table = Table(title="Summary")
    table.add_column("what")
    table.add_column("result")
    for record in records:
        table.add_row(record["action_id"], outcome_text(record))
    table.add_row("recharges flown", str(recorder.count("recharge")))
    table.add_row("hand-overs seen", str(handovers))
    if truth is not None:
        delivered = ", ".join(f"{d.tool}->{d.worker_id} by {d.uav_id}" for d in truth.deliveries)
        table.add_row("tools delivered (simulator)", delivered or "none")
        low = [f"{v.uav_id} {100 * v.battery_fraction:.0f} %" for v in truth.vehicles]
        table.add_row("batteries at the end", ", ".join(low))
    return table


def main(argv: list[str] | None = None) -> int:
    """Run the demo; 0 only if every action completed."""
    parser = argparse.ArgumentParser(
        prog="linecrew demo",
        description=HELP,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    add_run_arguments(parser)
    parser.set_defaults(speedup=10.0)
    parser.add_argument("--timeout", type=float, default=600.0, help="give up after (wall s)")
    args = parser.parse_args(argv)
    configure_logging(args.log_level, "plain", "demo")
    shutdown = Shutdown().install()
    console = Console()
    try:
        scenario = scenario_from(args)
        with LocalRun(scenario, options_from(args)) as run:
            console.print(
                f"[bold]linecrew demo[/]: {scenario.description.strip()}\n"
                f"gateway {run.url} · logs {run.run_dir}/ · x{args.speedup:g}"
            )
            console.print(intro(scenario, args.speedup), markup=False, highlight=False)
            start = time.time() * args.speedup
            narrator = Narrator(start)
            assert run.bus is not None
            run.bus.subscribe(run.keys.events(), GsEvent, lambda _k, e: narrator.inbox.put(e))
            gateway = run.gateway()
            records, recorder = run_mission(
                gateway, scenario, args.speedup, args.timeout, shutdown, console, narrator=narrator
            )
            truth = run.bus.query(run.keys.sim("state"), GetSimState(), SimState, 5.0)
    except (ScenarioError, StartError, GatewayError, SecureProfileError) as exc:
        print(f"linecrew demo: {exc}", file=sys.stderr)
        return 1
    rows = [(uav, "", segs) for uav, segs in sorted(recorder.segments.items())]
    console.print(timeline(rows, start, time.time() * args.speedup, "Executed"))
    console.print(summary(records, recorder, truth, narrator.handovers))
    ok = bool(records) and all(r["state"] == "completed" for r in records)
    console.print(
        "[green]every action completed[/]" if ok else "[red]not every action completed[/]"
    )
    report_of(run.run_dir, console)
    return 0 if ok else 1


def report_of(run_dir: pathlib.Path, console: Console) -> pathlib.Path | None:
    """Write the run's report and print its path (a failure is reported, not raised:
    the mission's outcome stands)."""
    from linecrew.report import write_report

    try:
        path = write_report(run_dir)
    except Exception as exc:  # the report is extra: never mask the mission's result
        print(f"linecrew demo: no report: {exc}", file=sys.stderr)
        return None
    console.print(f"report: {path}", markup=False, highlight=False)
    return path
