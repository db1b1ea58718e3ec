"""A light stand-in for an onboard agent, for the ground-station bench and
tests: a real Zenoh client that declares the agent's token,
publishes telemetry at 5 Hz from a fixed position, and records the plans it
receives with their arrival times. It flies nothing."""

from __future__ import annotations

import threading
import time

from ground_station.planning import capacity_wh, home_station
from linecrew_runtime.bus import Bus, BusConfig
from proto import FlightState, GeoPoint, KeySpace, Plan, Role, Scenario, Telemetry


class LightAgent:
    """One fake UAV agent on the bus."""

    def __init__(self, config: BusConfig, scenario: Scenario, uav_id: str) -> None:
        self.uav_id = uav_id
        self.keys = KeySpace(scenario.site.id)
        spec = next(u for u in scenario.fleet.uavs if u.id == uav_id)
        self.capacity = capacity_wh(scenario.fleet, uav_id)
        self.position = home_station(scenario.site, spec).position
        self.plans: list[Plan] = []
        self.arrivals: list[float] = []  # time.perf_counter() at each plan's arrival
        self.bus = Bus.open(config)
        self.bus.subscribe(self.keys.plan(uav_id), Plan, self._on_plan)
        self._token = self.bus.declare_token(self.keys.alive(Role.AGENT, uav_id))
        self._speaking = threading.Event()
        self._speaking.set()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._beat, daemon=True)
        self._thread.start()

    def _on_plan(self, _key: str, plan: Plan) -> None:
        self.arrivals.append(time.perf_counter())
        self.plans.append(plan)

    def _beat(self) -> None:
        while not self._stop.wait(0.2):
            if self._speaking.is_set():
                self.bus.publish(self.keys.telemetry(self.uav_id), self.telemetry())

    def telemetry(self) -> Telemetry:
        """A landed, fully charged sample."""
        return Telemetry(
            uav_id=self.uav_id,
            stamp_s=time.time(),
            position=self.position,
            geo=GeoPoint(),
            battery_wh=self.capacity,
            battery_fraction=1.0,
            flight_state=FlightState.LANDED,
        )

    def go_silent(self) -> None:
        """Withdraw the token and stop telemetry (a cut link, seen from the ground)."""
        self._speaking.clear()
        self._token.close()

    def speak_again(self) -> None:
        """Token and telemetry are back."""
        self._token = self.bus.declare_token(self.keys.alive(Role.AGENT, self.uav_id))
        self._speaking.set()

    def latest(self) -> Plan | None:
        """The newest plan received."""
        return self.plans[-1] if self.plans else None

    def close(self) -> None:
        """Stop and leave the bus."""
        self._stop.set()
        self._thread.join()
        self.bus.close()
