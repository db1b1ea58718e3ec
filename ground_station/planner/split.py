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


def chunk(points: list[Vec3], service_s: list[float], speed_mps: float, m: int) -> list[list[int]]:
    """Split indices ``0..n-1`` into ``m`` contiguous chunks (min-max work)."""
    n = len(points)
    m = max(1, min(m, n))
    if m == 1:
        return [list(range(n))]
    serv = [0.0]
    for s in service_s:
        serv.append(serv[-1] + s)
    legs = [0.0]
    for i in range(1, n):
        legs.append(legs[-1] + dist(points[i - 1], points[i]) / speed_mps)

    def work(i: int, j: int) -> float:  # points i..j-1
        return serv[j] - serv[i] + legs[j - 1] - legs[i]

    inf = float("inf")
    # best[c][j]: (max work, total work) splitting the first j points into c chunks
    best = [[(inf, inf)] * (n + 1) for _ in range(m + 1)]
    cut = [[0] * (n + 1) for _ in range(m + 1)]
    best[0][0] = (0.0, 0.0)
    for c in range(1, m + 1):
        for j in range(c, n + 1):
            for i in range(c - 1, j):
                prev = best[c - 1][i]
                if prev[0] == inf:
                    continue
                w = work(i, j)
                cand = (max(prev[0], w), prev[1] + w)
                if cand < best[c][j]:
                    best[c][j] = cand
                    cut[c][j] = i
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
