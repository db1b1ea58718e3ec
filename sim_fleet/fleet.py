"""The fleet runner: one World, one MAVLink endpoint per vehicle, a fixed-rate loop.

Why asyncio and not threads: all endpoints are non-blocking UDP sockets on one
event loop, and the world is stepped by a task on that same loop, so every
read and write of the world happens on one thread with no locks. 50 vehicles
cost 50 sockets, not 50 threads, and pymavlink's encode/decode is pure
computation that would not run in parallel under the GIL anyway.

Time: each tick measures the wall time since the previous one (injected
``clock``, monotonic) and advances the world by ``speedup`` times that, so
motion, energy and charging all run K times faster, consistently. A stall
longer than ``max_tick_gap`` periods is not replayed in one jump.

Sync callers (tests, a later CLI) can use ``FleetThread``, which runs the
loop in a background thread and hands calls into it.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import contextlib
import functools
import logging
import threading
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TypeVar

from proto.scenario import Scenario
from sim_fleet.mavlink_endpoint import Addr, VehicleEndpoint
from sim_fleet.params import AutopilotParams
from sim_fleet.streams import TelemetryRates
from sim_fleet.world import World

log = logging.getLogger(__name__)
T = TypeVar("T")


@dataclass(frozen=True, kw_only=True)
class FleetConfig:
    speedup: float = 1.0  # simulated seconds per wall second
    rate_hz: float = 20.0  # world steps (and telemetry checks) per wall second
    host: str = "127.0.0.1"  # address the endpoints bind to
    base_port: int = 14560  # vehicle i (0-based) listens on base_port + i; 0: any free port
    static_peers: tuple[Addr, ...] = ()  # always sent telemetry (SITL "udpclient")
    signing_keys: Mapping[str, bytes] = field(default_factory=dict)  # vehicle id -> MAVLink key
    rates: TelemetryRates = field(default_factory=TelemetryRates)
    params: AutopilotParams = field(default_factory=AutopilotParams)
    physics_step_s: float = 0.05  # fixed physics step, simulated seconds
    max_tick_gap: float = 5.0  # longest wall gap replayed, in tick periods


class Fleet:
    def __init__(
        self,
        scenario: Scenario,
        config: FleetConfig | None = None,
        *,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.config = config or FleetConfig()
        self.clock = clock
        self.world = World(
            scenario, params=self.config.params, physics_step_s=self.config.physics_step_s
        )
        self.endpoints: dict[str, VehicleEndpoint] = {}
        self.ticks = 0
        self.busy_s = 0.0  # wall time spent stepping and sending (for benchmarks)
        self._transports: list[asyncio.DatagramTransport] = []
        self._stop: asyncio.Event | None = None
        self._loop: asyncio.AbstractEventLoop | None = None

    @property
    def ports(self) -> dict[str, int]:
        """vehicle id -> UDP port its endpoint listens on."""
        return {vid: ep.port for vid, ep in self.endpoints.items()}

    async def start(self) -> None:
        """Bind every vehicle's endpoint; raises OSError if a port is taken."""
        self._loop = asyncio.get_running_loop()
        self._stop = asyncio.Event()
        cfg = self.config
        try:
            for i, (vid, vehicle) in enumerate(self.world.vehicles.items()):
                port = cfg.base_port + i if cfg.base_port else 0
                endpoint = functools.partial(
                    VehicleEndpoint,
                    self.world,
                    vehicle,
                    rates=cfg.rates,
                    static_peers=cfg.static_peers,
                    signing_key=cfg.signing_keys.get(vid),
                )
                transport, ep = await self._loop.create_datagram_endpoint(
                    endpoint, local_addr=(cfg.host, port)
                )
                self._transports.append(transport)
                self.endpoints[vid] = ep
        except OSError:
            self._close()
            raise
        log.info("fleet of %d listening on %s", len(self.endpoints), self.ports)

    async def run(self) -> None:
        """Step the world at ``rate_hz`` until ``stop()``; binds first if needed."""
        if not self.endpoints:
            await self.start()
        assert self._stop is not None
        period = 1.0 / self.config.rate_hz
        last = self.clock()
        next_tick = last + period
        try:
            while not self._stop.is_set():
                delay = next_tick - self.clock()
                if delay > 0:
                    try:
                        await asyncio.wait_for(self._stop.wait(), timeout=delay)
                        break
                    except TimeoutError:
                        pass
                now = self.clock()
                wall_dt = min(now - last, period * self.config.max_tick_gap)
                last = now
                next_tick = max(next_tick + period, now)
                self.tick(wall_dt)
                self.busy_s += self.clock() - now
        finally:
            self._close()

    def tick(self, wall_dt_s: float) -> None:
        """Advance by ``wall_dt_s`` wall seconds (x speed-up) and send what is due."""
        self.world.step(wall_dt_s * self.config.speedup)
        for ep in self.endpoints.values():
            ep.tick()
        self.ticks += 1

    def stop(self) -> None:
        """Ask ``run()`` to finish; safe to call from any thread, more than once."""
        loop, ev = self._loop, self._stop
        if loop is None or ev is None or loop.is_closed():
            return
        # the loop may close between the check and the call
        with contextlib.suppress(RuntimeError):
            loop.call_soon_threadsafe(ev.set)

    def _close(self) -> None:
        for t in self._transports:
            t.close()
        self._transports.clear()


class FleetThread:
    """Runs a ``Fleet`` on its own event loop in a daemon thread."""

    def __init__(self, fleet: Fleet) -> None:
        self.fleet = fleet
        self._thread: threading.Thread | None = None
        self._started = threading.Event()
        self._error: BaseException | None = None
        self._loop: asyncio.AbstractEventLoop | None = None

    def start(self, timeout_s: float = 10.0) -> FleetThread:
        self._thread = threading.Thread(target=self._main, name="sim-fleet", daemon=True)
        self._thread.start()
        if not self._started.wait(timeout_s):
            raise TimeoutError("fleet did not start")
        if self._error is not None:
            raise self._error
        return self

    def _main(self) -> None:
        async def main() -> None:
            self._loop = asyncio.get_running_loop()
            try:
                await self.fleet.start()
            except BaseException as exc:
                self._error = exc
                self._started.set()
                raise
            self._started.set()
            await self.fleet.run()

        try:
            asyncio.run(main())
        except Exception:
            if self._error is None:
                log.exception("fleet loop crashed")

    def call(self, fn: Callable[[], T], timeout_s: float = 5.0) -> T:
        """Run ``fn()`` on the fleet's loop thread (safe world access) and return its result."""
        assert self._loop is not None

        async def run() -> T:
            return fn()

        fut: concurrent.futures.Future[T] = asyncio.run_coroutine_threadsafe(run(), self._loop)
        return fut.result(timeout_s)

    def stop(self, timeout_s: float = 10.0) -> None:
        self.fleet.stop()
        if self._thread is not None:
            self._thread.join(timeout_s)

    def __enter__(self) -> FleetThread:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()
