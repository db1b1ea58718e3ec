"""A readable text Gantt chart of a plan (rich), for the CLI."""

from __future__ import annotations

from rich.table import Table
from rich.text import Text

from ground_station.planner.result import Solution, Unplaced

GLYPH = {
    "inspect": ("I", "green"),
    "monitor": ("M", "blue"),
    "pick": ("P", "magenta"),
    "deliver": ("D", "red"),
    "recharge": ("R", "yellow"),
    "wait": ("w", "bright_black"),
    "home": ("H", "cyan"),
}


def gantt(plan: Solution, now_s: float = 0.0, width: int = 72) -> Table:
    """One row per UAV; a column is ``span / width`` seconds; ``-`` is flight."""
    end = max((u.steps[-1].end_s for u in plan.uavs if u.steps), default=now_s + 1.0)
    span = max(end - now_s, 1e-9)
    table = Table(title=f"Plan: {span:.0f} s, one column = {span / width:.1f} s")
    table.add_column("UAV", no_wrap=True)
    table.add_column("timeline", no_wrap=True)
    table.add_column("steps", justify="right")
    for u in plan.uavs:
        cells = [(" ", "")] * width

        def col(t: float) -> int:
            return min(width - 1, int((t - now_s) / span * (width - 1)))

        for s in u.steps:  # flights first, so that short services stay visible
            for i in range(col(s.start_s), col(s.arrive_s)):
                cells[i] = ("-", "white")
        for s in u.steps:
            glyph = GLYPH.get(s.kind, ("?", ""))
            if s.kind == "wait" and s.end_s - s.arrive_s <= 0:
                continue
            for i in range(col(s.arrive_s), max(col(s.end_s), col(s.arrive_s) + 1)):
                if glyph[0] != "w" or cells[i][0] in " -":
                    cells[i] = glyph
        line = Text()
        for ch, style in cells:
            line.append(ch, style=style)
        table.add_row(u.uav_id, line, str(len(u.steps)))
    legend = "  ".join(f"{g} {k}" for k, (g, _) in GLYPH.items())
    table.caption = f"{legend}  - flight"
    return table


def unplaced_table(items: tuple[Unplaced, ...]) -> Table:
    table = Table(title="Unplaced")
    table.add_column("action")
    table.add_column("part")
    table.add_column("reason")
    for x in items:
        table.add_row(x.action_id, "-" if x.part is None else str(x.part), x.reason)
    return table
