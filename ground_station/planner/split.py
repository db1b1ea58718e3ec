"""Grouping an inspection's waypoints into contiguous, short routes.

Waypoints keep their given order (a patrol along the line); a split cuts the
ordered list into ``m`` contiguous chunks minimising the largest chunk's work
(service time plus the flight inside the chunk). Legs between chunks are not
flown by anyone, so cuts fall on long legs and each UAV gets a compact
stretch rather than a round-robin scatter.
"""

from __future__ import annotations

from math import dist

from ground_station.planner.model import Vec3


def chunk_all(
    points: list[Vec3], service_s: list[float], speed_mps: float, max_m: int
) -> dict[int, list[list[int]]]:
    """Split indices ``0..n-1`` into ``m`` contiguous chunks (min-max work),
    for each ``m`` from 1 to ``min(max_m, n)`` (one table serves them all)."""
    n = len(points)
    top = min(max_m, n)
    serv = [0.0]
    for s in service_s:
        serv.append(serv[-1] + s)
    legs = [0.0]
    for i in range(1, n):
        legs.append(legs[-1] + dist(points[i - 1], points[i]) / speed_mps)
    inf = float("inf")
    # best[c][j]: (max work, total work) splitting the first j points into c chunks
    best = [[(inf, inf)] * (n + 1) for _ in range(top + 1)]
    cut = [[0] * (n + 1) for _ in range(top + 1)]
    best[0][0] = (0.0, 0.0)
    for c in range(1, top + 1):
        _fill_row(best[c - 1], best[c], cut[c], c, serv, legs)
    return {m: _cuts(cut, m, n) for m in range(1, top + 1)}


def _fill_row(
    prev: list[tuple[float, float]],
    row: list[tuple[float, float]],
    cut: list[int],
    c: int,
    serv: list[float],
    legs: list[float],
) -> None:
    """Best splits into ``c`` chunks from those into ``c - 1``; the work of
    points i..j-1 is their service plus the flight between them."""
    inf = float("inf")
    for j in range(c, len(row)):
        serv_j, legs_j = serv[j], legs[j - 1]
        for i in range(c - 1, j):
            p_max, p_sum = prev[i]
            if p_max == inf:
                continue
            w = serv_j - serv[i] + legs_j - legs[i]
            cand = (w if w > p_max else p_max, p_sum + w)
            if cand < row[j]:
                row[j] = cand
                cut[j] = i


def _cuts(cut: list[list[int]], m: int, n: int) -> list[list[int]]:
    out: list[list[int]] = []
    j = n
    for c in range(m, 0, -1):
        i = cut[c][j]
        out.append(list(range(i, j)))
        j = i
    out.reverse()
    return out


def fixed_split_count(n: int) -> int:
    """The paper's code: 1, 2 or 3 UAVs for up to 3, up to 6, or more waypoints."""
    return 1 if n <= 3 else 2 if n <= 6 else 3


def equal_chunks(n: int, m: int) -> list[list[int]]:
    """Contiguous chunks of (nearly) equal count, for the paper mode."""
    m = max(1, min(m, n))
    size, extra = divmod(n, m)
    out, start = [], 0
    for c in range(m):
        end = start + size + (1 if c < extra else 0)
        out.append(list(range(start, end)))
        start = end
    return out
