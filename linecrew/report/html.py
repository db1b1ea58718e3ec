"""The run report: one self-contained HTML page (inline CSS and SVG, no
script, no external asset) with the map, the timelines, the batteries and
the actions of a finished run."""

from __future__ import annotations

import datetime
import pathlib
from collections import Counter
from html import escape

from linecrew.report import svg
from linecrew.report.data import Run, Segment, load_run, tag

STYLE = """
body { font-family: sans-serif; margin: 2em auto; max-width: 960px; color: #222; }
h1 { font-size: 1.5em; margin-bottom: 0.2em; }
h2 { font-size: 1.15em; margin-top: 2em; border-bottom: 1px solid #ddd; }
p.meta, p.note { color: #555; }
table { border-collapse: collapse; width: 100%; font-size: 0.9em; }
th, td { border-bottom: 1px solid #e4e4e4; padding: 4px 6px; text-align: left; }
td { vertical-align: top; }
th { background: #f4f4f4; }
td.num { text-align: right; white-space: nowrap; }
.completed { color: #2ca02c; } .failed { color: #d62728; } .cancelled { color: #7f7f7f; }
svg { max-width: 100%; height: auto; display: block; }
"""


def _seconds(value: float | None) -> str:
    return "-" if value is None else f"{value:.0f} s"


def _section(ident: str, title: str, *parts: str) -> str:
    return f'<section id="{ident}"><h2>{escape(title)}</h2>{"".join(parts)}</section>'


def _note(words: str) -> str:
    return f'<p class="note">{escape(words)}</p>'


def _map_section(run: Run) -> str:
    tracks = run.tracks()
    parts = [svg.site_map(run.scenario, tracks)]
    if not any(tracks.values()):
        parts.append(_note("No telemetry in this run directory (flight.jsonl): no tracks."))
    return _section("map", "Site and flown tracks", *parts)


def _timeline_section(run: Run, executed: list[Segment]) -> str:
    epoch, planned, held = run.first_plan()
    times = [s.start_s for s in executed + planned] + [s.end_s for s in executed + planned]
    start, end = min([0.0, *times]), max([run.end_s, *times])
    plan_title = (
        f"first plan (epoch {epoch}, {held} of {len(run.actions)} actions)"
        if epoch >= 0
        else "first plan (none stored)"
    )
    panels = [("executed", executed), (plan_title, planned)]
    parts = [svg.gantt(run.uav_ids, panels, start, end)]
    if not executed:
        parts.append(_note("No agent status nor outcome recorded (flight.jsonl): none executed."))
    parts.append(
        _note(
            "Executed: from each agent's reported current task to the task's outcome. "
            "Times are mission seconds since the run started; hover a bar for its task."
        )
    )
    return _section("timeline", "Timeline: executed and first plan", *parts)


def _battery_section(run: Run) -> str:
    curves = run.batteries()
    reserve = run.scenario.fleet.reserve_fraction
    parts = [svg.battery_curves(curves, reserve, 0.0, run.end_s)]
    if not any(curves.values()):
        parts.append(_note("No telemetry recorded: no battery curves."))
    return _section("batteries", "Batteries", *parts)


def _actions_section(run: Run, executed: list[Segment]) -> str:
    counts = Counter(str(r.state) for r in run.actions)
    flown: dict[str, set[str]] = {}
    for s in executed:
        if s.action_id:
            flown.setdefault(s.action_id, set()).add(s.uav_id)
    rows = []
    for record in run.actions:
        action = record.action
        what = {
            "deliver": lambda a: f"{a.tool} from {a.tool_station_id} to {a.worker_id}",
            "monitor": lambda a: f"{a.worker_id}, {a.uavs} UAV(s), {a.duration_s:g} s",
            "inspect": lambda a: f"{len(a.waypoints)} waypoints",
        }[tag(action)](action)
        uavs = sorted(flown.get(record.action_id, set())) or run.uavs_of(record.action_id)
        submitted = record.created_s - run.t0
        ended = run.ended_s(record.action_id)
        took = ended - submitted if ended is not None else None
        transitions = run.transitions.get(record.action_id, [])
        history = "; ".join(
            f"{t.to_state} at {t.stamp_s - run.t0:.0f} s" + (f" ({t.reason})" if t.reason else "")
            for t in transitions
        )
        state = escape(str(record.state))
        cells = [
            (escape(record.action_id), ""),
            (escape(tag(action)), ""),
            (escape(what), ""),
            (f'<span class="{state}">{state}</span>', ""),
            (f"{100 * record.progress:.0f} %", "num"),
            (escape(", ".join(uavs) or "-"), ""),
            (_seconds(submitted), "num"),
            (_seconds(ended), "num"),
            (_seconds(took), "num"),
            (escape(record.reason or "-"), ""),
            (escape(history), ""),
        ]
        rows.append(
            "<tr>"
            + "".join(f'<td class="{c}">{v}</td>' if c else f"<td>{v}</td>" for v, c in cells)
            + "</tr>"
        )
    head = (
        "id",
        "kind",
        "what",
        "outcome",
        "progress",
        "UAVs",
        "submitted",
        "ended",
        "took",
        "reason",
        "transitions",
    )
    table = (
        "<table><thead><tr>"
        + "".join(f"<th>{h}</th>" for h in head)
        + "</tr></thead><tbody>"
        + "".join(rows)
        + "</tbody></table>"
    )
    summary = ", ".join(f"{n} {state}" for state, n in counts.items()) or "no actions"
    return _section("actions", "Actions", svg.outcome_bar(dict(counts)), _note(summary), table)


def render(run: Run) -> str:
    """The whole page."""
    executed = run.executed()
    about = run.about
    started = about.get("started_s")
    when = (
        datetime.datetime.fromtimestamp(started, datetime.UTC).strftime("%Y-%m-%d %H:%M:%S UTC")
        if started
        else "unknown start"
    )
    speed = f"x{about['speedup']:g}" if about.get("speedup") else "speed-up unknown"
    title = f"linecrew run report: {run.scenario.name} ({run.run_dir.name})"
    meta = (
        f"{when} · {speed} · site {run.scenario.site.id} · {len(run.uav_ids)} UAVs "
        f"({', '.join(run.uav_ids)}) · {len(run.events)} events · run directory {run.run_dir}"
    )
    body = [
        f"<h1>{escape(title)}</h1>",
        f'<p class="meta">{escape(meta)}</p>',
        _map_section(run),
        _timeline_section(run, executed),
        _battery_section(run),
        _actions_section(run, executed),
    ]
    return (
        '<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
        f"<title>{escape(title)}</title><style>{STYLE}</style></head>"
        f"<body>{''.join(body)}</body></html>\n"
    )


def write_report(run_dir: pathlib.Path, output: pathlib.Path | None = None) -> pathlib.Path:
    """Write the report of ``run_dir`` (default ``run_dir/report.html``); its path."""
    run = load_run(run_dir)
    path = output or run_dir / "report.html"
    path.write_text(render(run), encoding="utf-8")
    return path
