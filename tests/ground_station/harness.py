"""A mission manager with a real store and planner, and the fake outside
world it talks to (recorded plans and events, a hand-driven clock).

Requests and reports only trigger the planning worker; ``settle()`` runs the
pending replans synchronously, so tests drive planning deterministically.
The helpers here settle after each step."""

from __future__ import annotations

from ground_station.event_log import EventLog
from ground_station.fleet_monitor import FleetMonitor
from ground_station.missions import MissionManager
from ground_station.replan_jobs import ImproveSettings
from ground_station.replanner import Replanner
from ground_station.store import Store
from linecrew_runtime.scenarios import load
from proto import (
    FlightState,
    GeoPoint,
    GsEvent,
    Plan,
    SubmitAction,
    Telemetry,
)

ALL = ("uav-1", "uav-2", "uav-3")
"""The paper fleet."""


class Harness:
    """Builds the ground station's components around one SQLite file."""

    def __init__(self, db_path: str, now: float = 1000.0, improve: bool = False) -> None:
        self.scenario = load("paper")
        self.now = now
        self.sent: list[Plan] = []
        self.events: list[GsEvent] = []
        self.store = Store(db_path)
        uav_ids = [u.id for u in self.scenario.fleet.uavs]
        self.monitor = FleetMonitor(uav_ids, 5.0, mission_clock=lambda: self.now)
        log = EventLog(self.store, self.events.append, lambda: self.now)
        self.replanner = Replanner(
            scenario=self.scenario,
            store=self.store,
            monitor=self.monitor,
            events=log,
            send=self.sent.append,
            improve=ImproveSettings(enabled=improve),
        )
        self.manager = MissionManager(
            scenario=self.scenario,
            store=self.store,
            monitor=self.monitor,
            events=log,
            replanner=self.replanner,
            clock=lambda: self.now,
            improve=improve,
        )

    def settle(self, improve: bool = False) -> None:
        """Run the replans the triggers so far asked for (and, with
        ``improve``, the improvement attempts due)."""
        self.manager.worker.settle(improve=improve)

    def telemetry(self, uav_id: str, battery_wh: float | None = None) -> Telemetry:
        """A landed-at-home sample of ``uav_id`` (full battery by default)."""
        spec = next(u for u in self.scenario.fleet.uavs if u.id == uav_id)
        capacity = self.scenario.fleet.type_of(uav_id).battery_wh
        energy = capacity if battery_wh is None else battery_wh
        return Telemetry(
            uav_id=uav_id,
            stamp_s=self.now,
            position=self.scenario.site.station(spec.home_station).position,
            geo=GeoPoint(),
            battery_wh=energy,
            battery_fraction=energy / capacity,
            flight_state=FlightState.LANDED,
        )

    def bring_up(self, *uav_ids: str) -> None:
        """The agents of ``uav_ids`` appear (token + telemetry)."""
        for uav_id in uav_ids:
            self.monitor.on_token(uav_id, True, self.now)
            self.monitor.on_telemetry(self.telemetry(uav_id), self.now)
        self.manager.on_fleet_changes(self.monitor.check(self.now))
        self.settle()

    def heartbeat(self, *uav_ids: str) -> None:
        """Fresh telemetry from ``uav_ids``."""
        for uav_id in uav_ids:
            self.monitor.on_telemetry(self.telemetry(uav_id), self.now)

    def advance(self, seconds: float) -> None:
        """Move the clock and run the watchdog."""
        self.now += seconds
        self.manager.retry_unsaved()
        self.manager.on_fleet_changes(self.monitor.check(self.now))
        self.settle()

    def submit(self, name: str, request_id: str | None = None):
        """Submit the paper scenario's scripted action ``name``."""
        scripted = next(a for a in self.scenario.actions if a.id == name)
        request = SubmitAction(
            request_id=request_id or f"req-{name}", action=scripted.action, action_id=name
        )
        self.manager.submit(request)
        self.settle()
        return self.manager.book.record(name)

    def latest(self, uav_id: str) -> Plan:
        """The last plan sent to ``uav_id``."""
        return [p for p in self.sent if p.uav_id == uav_id][-1]
