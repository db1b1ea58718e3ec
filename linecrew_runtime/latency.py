"""Latency figures shared by the benches: nearest-rank percentiles of
durations in seconds, reported in milliseconds (None without samples)."""

from __future__ import annotations

import statistics
from collections.abc import Sequence


def percentile_ms(values_s: Sequence[float], q: float) -> float | None:
    """The ``q`` quantile (0..1, nearest rank) of ``values_s``, in ms."""
    if not values_s:
        return None
    ordered = sorted(values_s)
    if q == 0.5:
        return statistics.median(ordered) * 1e3
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))] * 1e3


def summary_ms(values_s: Sequence[float]) -> dict[str, float | None]:
    """p50 / p99 / max of ``values_s`` in ms."""
    return {
        "p50_ms": percentile_ms(values_s, 0.5),
        "p99_ms": percentile_ms(values_s, 0.99),
        "max_ms": max(values_s) * 1e3 if values_s else None,
    }
