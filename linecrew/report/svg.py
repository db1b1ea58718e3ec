"""Inline SVG drawings of a run: the site map with flown tracks, Gantt
charts, battery curves, an outcome bar. Plain strings, no dependencies;
every text is escaped."""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from html import escape
from typing import TypedDict

from linecrew.report.data import Segment
from proto.scenario import Scenario

PALETTE = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf", "#8c564b", "#e377c2")
KIND_COLOURS = {
    "inspect": "#2ca02c",
    "monitor": "#1f77b4",
    "pick": "#e377c2",
    "deliver": "#d62728",
    "recharge": "#ffbf00",
    "wait": "#c7c7c7",
    "home": "#17becf",
}
RESULT_COLOURS = {"completed": "#2ca02c", "failed": "#d62728", "cancelled": "#7f7f7f"}
FAILED = {"failed", "aborted"}


class Box(TypedDict):
    """A rectangle's attributes."""

    x: float
    y: float
    width: float
    height: float


class Outline(TypedDict, total=False):
    """A shape's paint attributes."""

    fill: str
    stroke: str
    stroke_width: float


def colour_of(index: int) -> str:
    """The colour of the ``index``-th UAV."""
    return PALETTE[index % len(PALETTE)]


def el(tag: str, content: str = "", /, tip: str = "", **attrs: object) -> str:
    """One element; ``font_size=`` becomes ``font-size``; floats get one
    decimal; ``tip`` becomes a ``<title>`` (a hover text); ``content`` is
    markup (escape text with :func:`text`)."""
    parts = []
    for key, value in attrs.items():
        shown = f"{value:.1f}" if isinstance(value, float) else str(value)
        parts.append(f' {key.rstrip("_").replace("_", "-")}="{escape(shown)}"')
    inner = (f"<title>{escape(tip)}</title>" if tip else "") + content
    return f"<{tag}{''.join(parts)}>{inner}</{tag}>"


def text(x: float, y: float, words: str, tip: str = "", **attrs: object) -> str:
    """A ``<text>`` at ``x, y``."""
    return el("text", escape(words), tip=tip, x=float(x), y=float(y), **attrs)


def points(coords: Iterable[tuple[float, float]]) -> str:
    """An SVG ``points`` list."""
    return " ".join(f"{x:.1f},{y:.1f}" for x, y in coords)


def svg(width: float, height: float, body: Iterable[str], label: str) -> str:
    """The outer ``<svg>`` (inline in HTML: no external anything)."""
    return el(
        "svg",
        "".join(body),
        xmlns="http://www.w3.org/2000/svg",
        viewBox=f"0 0 {width:.0f} {height:.0f}",
        width=f"{width:.0f}",
        height=f"{height:.0f}",
        role="img",
        aria_label=label,
        font_family="sans-serif",
        font_size=11,
    )


def ticks(low: float, high: float, count: int = 6) -> list[float]:
    """Round tick values covering ``low .. high``."""
    raw = max(high - low, 1e-9) / count
    step = 10 ** math.floor(math.log10(raw))
    for factor in (1, 2, 5, 10):
        if raw <= factor * step:
            step *= factor
            break
    first = math.ceil(low / step) * step
    return [first + i * step for i in range(int((high - first) / step) + 1)]


def site_map(
    scenario: Scenario, tracks: dict[str, list[tuple[float, float, float]]], size: int = 640
) -> str:
    """Towers, lines, stations, tool stations and workers (ENU metres, north
    up) with every UAV's flown track."""
    site = scenario.site
    features = [t.position for t in site.towers] + [s.position for s in site.stations]
    features += [s.position for s in site.tool_stations] + [w.position for w in site.workers]
    xy = [(p.x_m, p.y_m) for p in features] + [(x, y) for tr in tracks.values() for _, x, y in tr]
    xs, ys = [p[0] for p in xy] or [0.0], [p[1] for p in xy] or [0.0]
    span = max(max(xs) - min(xs), max(ys) - min(ys), 10.0) * 1.1
    cx, cy = (max(xs) + min(xs)) / 2, (max(ys) + min(ys)) / 2
    margin, legend = 30, 18 * max(1, len(tracks))
    scale = (size - 2 * margin) / span

    def at(x: float, y: float) -> tuple[float, float]:
        return margin + (x - cx + span / 2) * scale, margin + (cy + span / 2 - y) * scale

    body = [el("rect", width=size, height=size + legend, fill="#fbfbf8")]
    for tick in ticks(cx - span / 2, cx + span / 2):
        x = at(tick, cy)[0]
        body.append(el("line", x1=x, y1=margin, x2=x, y2=size - margin, stroke="#eee"))
        body.append(text(x, size - margin + 14, f"{tick:g}", text_anchor="middle", fill="#888"))
    for tick in ticks(cy - span / 2, cy + span / 2):
        y = at(cx, tick)[1]
        body.append(el("line", x1=margin, y1=y, x2=size - margin, y2=y, stroke="#eee"))
        body.append(text(margin - 4, y + 4, f"{tick:g}", text_anchor="end", fill="#888"))
    body.append(text(size - margin, margin - 8, "metres east, north up", text_anchor="end"))
    towers = {t.id: t for t in site.towers}
    for line in site.lines:
        path = [at(towers[t].position.x_m, towers[t].position.y_m) for t in line.tower_ids]
        body.append(
            el(
                "polyline",
                tip=f"line {line.id}",
                points=points(path),
                fill="none",
                stroke="#555",
                stroke_width=2,
                stroke_dasharray="6 3",
            )
        )
    for tower in site.towers:
        x, y = at(tower.position.x_m, tower.position.y_m)
        tip = f"tower {tower.id} ({tower.position.z_m:g} m high)"
        triangle = points([(x, y - 7), (x + 6, y + 5), (x - 6, y + 5)])
        body.append(el("polygon", tip=tip, points=triangle, fill="#444"))
        body.append(text(x + 8, y - 4, tower.id, fill="#444"))
    for station in site.stations:
        x, y = at(station.position.x_m, station.position.y_m)
        tip = f"charging station {station.id} ({station.pads} pads)"
        square: Box = {"x": x - 6, "y": y - 6, "width": 12, "height": 12}
        body.append(el("rect", tip=tip, **square, fill="#fff", stroke="#b8860b", stroke_width=2))
        body.append(text(x + 8, y + 12, station.id, fill="#b8860b"))
    for tools in site.tool_stations:
        x, y = at(tools.position.x_m, tools.position.y_m)
        tip = f"tool station {tools.id}: {', '.join(t.name for t in tools.tools)}"
        diamond = points([(x, y - 4), (x + 4, y), (x, y + 4), (x - 4, y)])
        body.append(el("polygon", tip=tip, points=diamond, fill="#e377c2"))
    for worker in site.workers:
        x, y = at(worker.position.x_m, worker.position.y_m)
        body.append(el("circle", tip=f"worker {worker.id}", cx=x, cy=y, r=5, fill="#ff7f0e"))
        body.append(text(x + 7, y + 4, worker.id, fill="#c05f00"))
    for index, (uav, track) in enumerate(tracks.items()):
        colour = colour_of(index)
        if track:
            line_pts = points(at(x, y) for _, x, y in track)
            body.append(
                el(
                    "polyline",
                    tip=f"{uav} track",
                    points=line_pts,
                    fill="none",
                    stroke=colour,
                    stroke_width=1.6,
                    stroke_opacity=0.8,
                )
            )
            end_x, end_y = at(track[-1][1], track[-1][2])
            body.append(el("circle", tip=f"{uav} at the end", cx=end_x, cy=end_y, r=3, fill=colour))
        ly = size + 4 + 18 * index
        body.append(
            el("line", x1=margin, y1=ly, x2=margin + 24, y2=ly, stroke=colour, stroke_width=3)
        )
        count = len(track)
        note = f"{count} telemetry point{'s' * (count != 1)}" if track else "no track recorded"
        body.append(text(margin + 30, ly + 4, f"{uav} ({note})"))
    return svg(size, size + legend, body, "site map with flown tracks")


def gantt(
    rows: Sequence[str],
    panels: Sequence[tuple[str, list[Segment]]],
    start_s: float,
    end_s: float,
    width: int = 900,
) -> str:
    """One panel per ``(title, segments)`` (e.g. executed, first plan), one
    row per UAV, on a shared time axis in seconds since the run started."""
    label_w, row_h, head = 90, 20, 22
    span = max(end_s - start_s, 1.0)
    plot_w = width - label_w - 20

    def x_of(t: float) -> float:
        return label_w + (min(max(t, start_s), end_s) - start_s) / span * plot_w

    body, y = [], 0.0
    for title, segments in panels:
        body.append(text(4, y + 15, title, font_weight="bold"))
        y += head
        for r, uav in enumerate(rows):
            top = y + r * row_h
            body.append(text(4, top + 14, uav))
            lane: Box = {"x": label_w, "y": top + 2, "width": plot_w, "height": row_h - 4}
            body.append(el("rect", **lane, fill="#f4f4f4"))
            for s in (s for s in segments if s.uav_id == uav):
                x0, x1 = x_of(s.start_s), x_of(s.end_s)
                tip = f"{s.task_id} ({s.kind}) {s.start_s:.0f}-{s.end_s:.0f} s"
                tip += (f" {s.result}" if s.result else "") + (f": {s.reason}" if s.reason else "")
                bar: Box = {"x": x0, "y": top + 3, "width": max(x1 - x0, 1.0), "height": row_h - 6}
                outline: Outline = (
                    {"stroke": "#d62728", "stroke_width": 2} if s.result in FAILED else {}
                )
                colour = KIND_COLOURS.get(s.kind, "#999")
                body.append(el("rect", tip=tip, **bar, fill=colour, **outline))
        y += len(rows) * row_h + 8
    for tick in ticks(start_s, end_s, 8):
        x = x_of(tick)
        body.append(el("line", x1=x, y1=0, x2=x, y2=y, stroke="#ccc", stroke_dasharray="2 3"))
        body.append(text(x, y + 12, f"{tick:g} s", text_anchor="middle", fill="#666"))
    y += 20
    lx = label_w
    for kind, colour in KIND_COLOURS.items():
        body.append(el("rect", x=lx, y=y, width=12, height=10, fill=colour))
        body.append(text(lx + 16, y + 9, kind))
        lx += 90
    failed: Outline = {"fill": "#fff", "stroke": "#d62728", "stroke_width": 2}
    body.append(el("rect", x=lx, y=y, width=12, height=10, **failed))
    body.append(text(lx + 16, y + 9, "failed / aborted"))
    return svg(width, y + 16, body, "Gantt chart: executed and first plan")


def battery_curves(
    curves: dict[str, list[tuple[float, float]]],
    reserve: float,
    start_s: float,
    end_s: float,
    width: int = 900,
    height: int = 260,
) -> str:
    """Battery fraction over time, one line per UAV, with the fleet's reserve."""
    left, right, top, bottom = 44, 20, 10, 34
    times = [t for curve in curves.values() for t, _ in curve]
    t0, t1 = min([start_s, *times]), max([end_s, *times])
    t1 = max(t1, t0 + 1.0)
    plot_w, plot_h = width - left - right, height - top - bottom

    def at(t: float, f: float) -> tuple[float, float]:
        return left + (t - t0) / (t1 - t0) * plot_w, top + (1 - f) * plot_h

    frame: Box = {"x": left, "y": top, "width": plot_w, "height": plot_h}
    body = [el("rect", **frame, fill="#fbfbf8", stroke="#ddd")]
    for frac in (0.0, 0.25, 0.5, 0.75, 1.0):
        y = at(t0, frac)[1]
        body.append(el("line", x1=left, y1=y, x2=left + plot_w, y2=y, stroke="#eee"))
        body.append(text(left - 4, y + 4, f"{frac:.0%}", text_anchor="end", fill="#666"))
    for tick in ticks(t0, t1, 8):
        x = at(tick, 0)[0]
        body.append(text(x, top + plot_h + 14, f"{tick:g} s", text_anchor="middle", fill="#666"))
    ry = at(t0, reserve)[1]
    body.append(
        el(
            "line",
            tip=f"reserve {reserve:.0%}",
            x1=left,
            y1=ry,
            x2=left + plot_w,
            y2=ry,
            stroke="#d62728",
            stroke_dasharray="5 4",
        )
    )
    body.append(text(left + plot_w - 2, ry - 3, f"reserve {reserve:.0%}", text_anchor="end"))
    for index, (uav, curve) in enumerate(curves.items()):
        colour = colour_of(index)
        if curve:
            line_pts = points(at(t, f) for t, f in curve)
            body.append(
                el(
                    "polyline",
                    tip=f"{uav} battery",
                    points=line_pts,
                    fill="none",
                    stroke=colour,
                    stroke_width=1.6,
                )
            )
        body.append(text(left + 8 + 110 * index, height - 2, f"■ {uav}", fill=colour))
    return svg(width, height, body, "battery curves")


def outcome_bar(counts: dict[str, int], width: int = 900) -> str:
    """A stacked bar of the actions' final states."""
    total = max(sum(counts.values()), 1)
    body, x = [], 0.0
    for state, count in counts.items():
        w = count / total * width
        colour = RESULT_COLOURS.get(state, "#1f77b4")
        body.append(el("rect", tip=f"{state}: {count}", x=x, y=0, width=w, height=22, fill=colour))
        if w > 60:
            body.append(text(x + 6, 15, f"{state} {count}", fill="#fff"))
        x += w
    return svg(width, 22, body, "action outcomes")
