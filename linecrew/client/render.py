"""Terminal views of gateway answers (rich): actions, fleet, plan timeline."""

from __future__ import annotations

from typing import Any

from rich.table import Table
from rich.text import Text

from linecrew.planner_tools.gantt import GLYPH
from linecrew_runtime.clock import time_of_day


def actions_table(records: list[dict[str, Any]]) -> Table:
    """One row per action; the reason (why it failed, or its last change)
    wraps instead of being cut."""
    table = Table(title="Actions")
    for column in ("id", "kind", "state", "progress", "priority"):
        table.add_column(column, no_wrap=True)
    table.add_column("reason", overflow="fold")
    for r in records:
        table.add_row(
            r["action_id"],
            r["action"]["type"],
            r["state"],
            f"{100 * r['progress']:.0f} %",
            f"{r['action']['priority']:g}",
            r.get("reason", ""),
        )
    return table


def silence_text(uav: dict[str, Any]) -> str:
    """``silent since HH:MM:SS, N s`` (mission clock) for a silent UAV, else ""."""
    silent, since = uav.get("silent_s"), uav.get("silent_since_s")
    if not silent:
        return ""
    began = f" since {time_of_day(since)}," if since is not None else ""
    return f"silent{began} {silent:.0f} s"


def _task_text(uav: dict[str, Any], status: dict[str, Any]) -> str:
    """The task the agent reports; a silent UAV's tasks are unknown."""
    unknown = uav.get("unknown_tasks") or []
    task = status.get("task_id") or "-"
    if not unknown:
        return task
    more = f", +{len(unknown) - 1} pending" if len(unknown) > 1 else ""
    return f"{unknown[0]} unknown{more}"


def fleet_table(uavs: list[dict[str, Any]]) -> Table:
    """One row per UAV."""
    table = Table(title="Fleet")
    for column in ("uav", "state", "battery", "position (m)", "task", "epoch"):
        table.add_column(column)
    for u in uavs:
        tel, status = u.get("telemetry") or {}, u.get("status") or {}
        pos = tel.get("position")
        silence, control = silence_text(u), u.get("control")
        state = f"{u['state']} ({silence})" if silence else u["state"]
        if status.get("holding_for"):
            state += f", holding off for {status['holding_for']}"
        table.add_row(
            u["uav_id"],
            f"{state}, operator: {control}" if control else state,
            f"{100 * tel['battery_fraction']:.0f} %" if tel else "-",
            f"{pos['x_m']:.0f}, {pos['y_m']:.0f}, {pos['z_m']:.0f}" if pos else "-",
            _task_text(u, status),
            str(status.get("epoch", "-")),
        )
    return table


Segment = tuple[float, float, str]
"""(start_s, end_s, task kind) on the mission clock."""


def timeline(
    rows: list[tuple[str, str, list[Segment]]],
    start_s: float,
    end_s: float,
    title: str,
    width: int = 64,
) -> Table:
    """One row per ``(label, note, segments)`` on a shared axis from ``start_s`` to ``end_s``."""
    span = max(end_s - start_s, 1.0)
    table = Table(title=f"{title}: {span:.0f} s, one column = {span / width:.1f} s")
    table.add_column("UAV", no_wrap=True)
    table.add_column("", justify="right")
    table.add_column("timeline", no_wrap=True)
    for label, note, segments in rows:
        cells = [(" ", "")] * width
        for seg_start, seg_end, kind in segments:
            a = max(0, int((seg_start - start_s) / span * (width - 1)))
            b = max(a + 1, int((seg_end - start_s) / span * (width - 1)))
            for i in range(a, min(b, width)):
                cells[i] = GLYPH.get(kind, ("?", ""))
        line = Text()
        for char, style in cells:
            line.append(char, style=style)
        table.add_row(label, note, line)
    table.caption = "  ".join(f"{g} {k}" for k, (g, _) in GLYPH.items())
    return table


def plan_timeline(plans: list[dict[str, Any]], now_s: float, clock: str = "") -> Table:
    """The planned tasks of every UAV from ``now_s`` (mission seconds) on."""
    rows = [
        (p["uav_id"], f"e{p['epoch']}", [(t["start_s"], t["end_s"], t["type"]) for t in p["tasks"]])
        for p in plans
    ]
    end = max((t["end_s"] for p in plans for t in p["tasks"]), default=now_s + 1.0)
    title = f"Plan from now{f' ({clock})' if clock else ''}"
    return timeline(rows, now_s, max(end, now_s + 1.0), title)


def plan_quality(quality: dict[str, Any]) -> str:
    """One line on the live plan's quality, as ``GET /v1/plan/quality`` gives it."""
    objective = quality.get("objective_s")
    if objective is None:
        return "plan objective: not known yet"
    parts = [f"plan objective {objective:.1f} s (weight-averaged completion + makespan)"]
    ago = quality.get("improved_ago_s")
    parts.append(f"improved {ago:.0f} s ago" if ago is not None else "not improved yet")
    gap = quality.get("gap_to_best")
    if gap is not None:
        parts.append(f"{gap:.1%} above the best plan seen for this state")
    return "; ".join(parts)


def _relative(seconds: float) -> str:
    return f"{seconds:+.0f} s"


def plan_tasks(plans: list[dict[str, Any]], now_s: float) -> Table:
    """Every planned task with its start and end in mission seconds from
    ``now_s`` (negative: already begun or over)."""
    table = Table(title="Planned tasks (mission seconds from now)")
    for column in ("UAV", "epoch", "task", "kind", "action"):
        table.add_column(column, no_wrap=True)
    for column in ("start", "end", "lasts"):
        table.add_column(column, justify="right", no_wrap=True)
    for plan in plans:
        for task in plan["tasks"]:
            table.add_row(
                plan["uav_id"],
                str(plan["epoch"]),
                task["task_id"],
                task["type"],
                task.get("action_id") or "-",
                _relative(task["start_s"] - now_s),
                _relative(task["end_s"] - now_s),
                f"{task['end_s'] - task['start_s']:.0f} s",
            )
    if not table.rows:
        table.caption = "no UAV has a planned task"
    return table
