"""Scripted worker motion: straight lines between timed points (pure)."""

from __future__ import annotations

import itertools

from proto.geo import Point
from proto.site import Worker


def worker_position(worker: Worker, sim_time_s: float) -> Point:
    """Where ``worker`` is at ``sim_time_s`` along its path (start before it,
    last point after it)."""
    points = [(0.0, worker.position)] + [(p.at_s, p.position) for p in worker.path]
    points.sort(key=lambda item: item[0])
    if sim_time_s <= points[0][0]:
        return points[0][1]
    for (t0, a), (t1, b) in itertools.pairwise(points):
        if sim_time_s <= t1:
            f = (sim_time_s - t0) / (t1 - t0) if t1 > t0 else 1.0
            return Point(
                x_m=a.x_m + f * (b.x_m - a.x_m),
                y_m=a.y_m + f * (b.y_m - a.y_m),
                z_m=a.z_m + f * (b.z_m - a.z_m),
            )
    return points[-1][1]
