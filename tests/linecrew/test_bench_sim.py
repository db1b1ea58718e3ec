"""``linecrew bench sim`` measures a real fleet and prints its numbers."""

from __future__ import annotations

from linecrew.bench.sim import run


def test_bench_reports_rates_and_cpu():
    results = run(vehicles=5, seconds=1.0, rate_hz=20.0, speedup=1.0)
    assert results["vehicles"] == 5
    assert results["physics_hz"] > 0
    assert results["per_vehicle_msgs_per_s"] > 1  # heartbeats at least
    assert 0 < results["cpu_percent_of_one_core"] < 400
