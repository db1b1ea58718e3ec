"""``linecrew bench bus``: the bus measured over a real router on loopback.

Publish->receive latency for a telemetry-sized message at 10 Hz and at full
rate, full-rate throughput, query round trip, and how long a liveliness
watcher takes to see a peer vanish (``kill -9``, and frozen by ``SIGSTOP``,
which only the lease reveals).
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import signal
import statistics
import subprocess
import sys
import threading
import time

from linecrew.bench.child import wait_ready
from linecrew_runtime.bus.config import BusConfig
from linecrew_runtime.bus.router_process import router_process
from linecrew_runtime.bus.session import Bus
from linecrew_runtime.latency import summary_ms
from proto import (
    GeoPoint,
    GetHistory,
    HistoryReply,
    KeySpace,
    LinecrewError,
    Point,
    Role,
    Telemetry,
)

KEYS = KeySpace("bench")
Metrics = dict[str, float | None]
"""Metric name -> value (None: nothing measured)."""


def _telemetry(stamp: float) -> Telemetry:
    return Telemetry(
        uav_id="uav-1",
        stamp_s=stamp,
        position=Point(x_m=12.5, y_m=-4.25, z_m=20.0),
        geo=GeoPoint(lat_deg=37.41, lon_deg=-6.0, alt_m=32.0),
        battery_wh=88.5,
        battery_fraction=0.885,
        mode="GUIDED",
    )


def _latency(pub: Bus, sub: Bus, count: int, period_s: float) -> Metrics:
    """Send ``count`` messages every ``period_s`` (0: flat out); receive latencies."""
    key = KEYS.telemetry("uav-1")
    latencies: list[float] = []
    done = threading.Event()

    def on_message(_key: str, message: Telemetry) -> None:
        latencies.append(time.perf_counter() - message.stamp_s)
        if len(latencies) >= count:
            done.set()

    with sub.subscribe(key, Telemetry, on_message):
        _warm_up(pub, key, latencies)
        latencies.clear()
        started = time.perf_counter()
        for i in range(count):
            if period_s:
                time.sleep(max(0.0, started + i * period_s - time.perf_counter()))
            pub.publish(key, _telemetry(time.perf_counter()))
        done.wait(5.0)
        elapsed = time.perf_counter() - started
    result = summary_ms(latencies)
    result.update(sent=count, received=len(latencies), msgs_per_s=len(latencies) / elapsed)
    return result


def _warm_up(pub: Bus, key: str, received: list[float]) -> None:
    deadline = time.monotonic() + 10
    while not received and time.monotonic() < deadline:
        pub.publish(key, _telemetry(time.perf_counter()))
        time.sleep(0.02)


def _query_rtt(server: Bus, client: Bus, count: int) -> Metrics:
    loop = asyncio.new_event_loop()
    ready = threading.Event()
    stop = asyncio.Event()

    async def serve() -> None:
        with server.serve(KEYS.rpc("bench"), GetHistory, lambda _r: HistoryReply(events=[])):
            ready.set()
            await stop.wait()

    thread = threading.Thread(target=loop.run_until_complete, args=(serve(),))
    thread.start()
    ready.wait(5)
    query = GetHistory()
    deadline = time.monotonic() + 10
    warm = 0
    while warm < 20 and time.monotonic() < deadline:  # routed, and caches warm
        try:
            client.query(KEYS.rpc("bench"), query, HistoryReply, 2.0)
            warm += 1
        except LinecrewError:  # the queryable is not routed yet
            time.sleep(0.05)
    rtts: list[float] = []
    failed = 0
    for _ in range(count):
        started = time.perf_counter()
        try:
            client.query(KEYS.rpc("bench"), query, HistoryReply, 2.0)
        except LinecrewError:
            failed += 1
            continue
        rtts.append(time.perf_counter() - started)
    loop.call_soon_threadsafe(stop.set)
    thread.join(5)
    result = summary_ms(rtts)
    result.update(queries=len(rtts), failed=failed)
    return result


def hold_token(endpoint: str, key: str, lease_ms: int) -> None:
    """Child-process body: declare ``key`` and wait to be killed."""
    with Bus.open(BusConfig(connect=(endpoint,), lease_ms=lease_ms)) as bus:
        bus.declare_token(key)
        print("ready", flush=True)
        threading.Event().wait()


def _vanish_time(watcher: Bus, endpoint: str, lease_ms: int, sig: signal.Signals) -> float:
    key = KEYS.alive(Role.AGENT, f"victim-{sig.name.lower()}")
    events: dict[bool, float] = {}
    code = (
        f"from linecrew.bench.bus import hold_token; hold_token({endpoint!r}, {key!r}, {lease_ms})"
    )
    with watcher.watch_liveliness(
        key, lambda _k, alive: events.setdefault(alive, time.perf_counter())
    ):
        child = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE)
        try:
            wait_ready(child)
            deadline = time.monotonic() + 10
            while True not in events and time.monotonic() < deadline:
                time.sleep(0.005)
            killed = time.perf_counter()
            os.kill(child.pid, sig)
            while False not in events and time.monotonic() < deadline + lease_ms / 100:
                time.sleep(0.001)
        finally:
            child.kill()
            child.wait()
    return (events.get(False, float("nan")) - killed) * 1e3


def run(samples: int, lease_ms: int, repeats: int) -> dict[str, Metrics]:
    """Run every measurement; returns name -> metrics."""
    with router_process("bench", lease_ms) as endpoint:
        config = BusConfig(connect=(endpoint,), lease_ms=lease_ms)
        with Bus.open(config) as a, Bus.open(config) as b:
            results = {
                "pub->sub at 10 Hz": _latency(a, b, samples, 0.1),
                "pub->sub flat out": _latency(a, b, samples * 200, 0.0),
                "query round trip": _query_rtt(a, b, samples * 4),
            }
            for sig in (signal.SIGKILL, signal.SIGSTOP):
                times = [_vanish_time(b, endpoint, lease_ms, sig) for _ in range(repeats)]
                results[f"liveliness after {sig.name}"] = {
                    "lease_ms": lease_ms,
                    "mean_ms": statistics.fmean(times),
                    "max_ms": max(times),
                }
    return results


def _print_table(results: dict[str, Metrics]) -> None:
    from rich.console import Console
    from rich.table import Table

    table = Table(title="linecrew bench bus (loopback, through a router process)")
    table.add_column("measurement")
    table.add_column("result")
    for name, metrics in results.items():
        table.add_row(name, "  ".join(f"{k}={_number(v)}" for k, v in metrics.items()))
    Console().print(table)


def _number(value: float | None) -> str:
    if value is None:
        return "-"
    if isinstance(value, int) or abs(value) >= 100:
        return f"{value:,.0f}"
    return f"{value:.3g}"


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``linecrew bench bus``."""
    parser = argparse.ArgumentParser(prog="linecrew bench bus", description=__doc__)
    parser.add_argument("--samples", type=int, default=100, help="messages at 10 Hz")
    parser.add_argument("--lease-ms", type=int, default=1000, help="zenoh transport lease")
    parser.add_argument("--repeats", type=int, default=3, help="liveliness trials per signal")
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    args = parser.parse_args(argv)
    results = run(args.samples, args.lease_ms, args.repeats)
    if args.json:
        print(json.dumps(results, indent=2))
    else:
        _print_table(results)
    return 0
