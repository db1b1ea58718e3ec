"""``linecrew bench sim``: N simulated vehicles in one process, measured.

Runs the fleet for a while with a telemetry sink subscribed to every vehicle
(so every message is really encoded and sent) and reports the achieved
physics rate, telemetry messages per second, and the CPU the simulator used.
"""

from __future__ import annotations

import argparse
import json
import socket
import threading
import time

from linecrew_runtime.scenarios import load, with_fleet_size
from sim_fleet.fleet import Fleet, FleetConfig, FleetThread
from sim_fleet.streams import TelemetryRates


class _Sink:
    """A UDP socket that counts every datagram sent to it, on its own thread."""

    def __init__(self) -> None:
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(("127.0.0.1", 0))
        self.sock.settimeout(0.1)
        self.count = 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._drain, daemon=True)
        self._thread.start()

    def _drain(self) -> None:
        while not self._stop.is_set():
            try:
                self.sock.recv(4096)
                self.count += 1
            except TimeoutError:
                continue

    def close(self) -> None:
        """Stop counting and close the socket."""
        self._stop.set()
        self._thread.join()
        self.sock.close()


def run(vehicles: int, seconds: float, rate_hz: float, speedup: float) -> dict[str, float]:
    """Simulate ``vehicles`` for ``seconds`` of wall time; returns the numbers."""
    sink = _Sink()
    config = FleetConfig(
        speedup=speedup,
        rate_hz=rate_hz,
        base_port=0,
        static_peers=(sink.sock.getsockname(),),
        rates=TelemetryRates(stream_by_default=True),  # the sink never asks
    )
    scenario = with_fleet_size(load("paper"), vehicles)
    fleet = Fleet(scenario, config)
    with FleetThread(fleet):
        time.sleep(1.0)  # warm up: sockets bound, first messages out
        cpu0, wall0, busy0 = time.process_time(), time.monotonic(), fleet.busy_s
        ticks0, msgs0 = fleet.ticks, sink.count
        time.sleep(seconds)
        cpu, wall = time.process_time() - cpu0, time.monotonic() - wall0
        ticks, msgs, busy = fleet.ticks - ticks0, sink.count - msgs0, fleet.busy_s - busy0
    sink.close()
    return {
        "vehicles": vehicles,
        "physics_hz": ticks / wall,
        "telemetry_msgs_per_s": msgs / wall,
        "per_vehicle_msgs_per_s": msgs / wall / vehicles,
        "cpu_percent_of_one_core": 100.0 * cpu / wall,
        "sim_loop_busy_percent": 100.0 * busy / wall,
    }


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``linecrew bench sim``."""
    parser = argparse.ArgumentParser(prog="linecrew bench sim", description=__doc__)
    parser.add_argument("--vehicles", type=int, default=50)
    parser.add_argument("--seconds", type=float, default=10.0, help="measured wall time")
    parser.add_argument("--rate-hz", type=float, default=20.0, help="physics ticks per second")
    parser.add_argument("--speedup", type=float, default=1.0)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args(argv)
    results = run(args.vehicles, args.seconds, args.rate_hz, args.speedup)
    if args.json:
        print(json.dumps(results, indent=2))
    else:
        for name, value in results.items():
            print(f"{name:>28}  {value:.4g}")
    return 0
