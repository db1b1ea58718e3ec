"""The simulated world: vehicles, charging stations, tool stations and workers.

``World.step(dt_s)`` advances everything by ``dt_s`` simulated seconds in fixed
physics steps of ``physics_step_s`` (a remainder is carried to the next call),
so the trajectory is the same whatever the speed-up or the caller's tick.
Nothing here reads a clock or sleeps; the runner (``fleet``) or a test decides
how much time passes. Fault operations are plain methods on the
world and its vehicles so the later Zenoh fault service only has to call them.
``deliveries``, ``drops``, ``violations`` and ``watch`` are the ground truth
of outcomes. The world is built from the shared :class:`proto.scenario.Scenario`
(its site and fleet; the scripted actions are not the simulator's business),
whose points become the physics' tuples here.
"""

from __future__ import annotations

import logging
import math

from proto.scenario import Scenario
from proto.spots import spot_owners, spot_positions
from sim_fleet import physics
from sim_fleet.events import Severity
from sim_fleet.geo import GeoFrame, vec
from sim_fleet.modes import FlightState
from sim_fleet.params import AutopilotParams
from sim_fleet.physics import Vec3
from sim_fleet.recorder import FlightRecorder
from sim_fleet.rules import InteractionRules
from sim_fleet.safety import SEPARATION, SafetyMonitor, Violation
from sim_fleet.stations import ChargingStation
from sim_fleet.terrain import Ground
from sim_fleet.tools import Delivery, Drop, ToolStation, station_in_reach, worker_in_reach
from sim_fleet.vehicle import Vehicle
from sim_fleet.watch import WatchLog

log = logging.getLogger(__name__)


class World:
    def __init__(
        self,
        scenario: Scenario,
        *,
        params: AutopilotParams | None = None,
        physics_step_s: float = 0.05,
        first_sysid: int = 1,
    ) -> None:
        site, fleet = scenario.site, scenario.fleet
        if site.safety.ground_z_m != 0.0:
            raise ValueError(f"the simulator's ground is at z = 0, not {site.safety.ground_z_m}")
        self.rules = InteractionRules()
        self.geo = GeoFrame(site.origin)
        self.physics_step_s = physics_step_s
        self.time_s = 0.0
        self._pending_s = 0.0
        # landing spots by station (proto.spots), and whose home spot each is
        self.spots: dict[str, tuple[Vec3, ...]] = {
            s.id: tuple(vec(p) for p in spot_positions(s, fleet)) for s in site.stations
        }
        self.spot_owners = {s.id: tuple(spot_owners(s, fleet)) for s in site.stations}
        self.ground = Ground(self.spots.values(), self.rules.dock_radius_m)
        types = {t.name: t for t in fleet.types}
        self.vehicles: dict[str, Vehicle] = {}
        for i, spec in enumerate(fleet.uavs):
            home = self.spot_owners[spec.home_station].index(spec.id)
            self.vehicles[spec.id] = Vehicle(
                spec,
                types[spec.type],
                sysid=first_sysid + i,
                home=self.spots[spec.home_station][home],
                params=params,
                ground=self.ground.z_at,
            )
        self.charging = {s.id: ChargingStation(s) for s in site.stations}
        self.tool_stations = {
            t.id: ToolStation(t.id, vec(t.position), t.tools) for t in site.tool_stations
        }
        self.workers: dict[str, Vec3] = {w.id: vec(w.position) for w in site.workers}
        self.deliveries: list[Delivery] = []
        self.drops: list[Drop] = []
        spots = (p for points in self.spots.values() for p in points)
        self.safety = SafetyMonitor(site.safety, spots, self.rules.dock_radius_m)
        self.watch = WatchLog(self.rules)
        self.recorder = FlightRecorder()

    @property
    def violations(self) -> list[Violation]:
        """Safety violations so far, in order (ground truth, see ``safety``)."""
        return self.safety.violations

    def vehicle(self, vehicle_id: str) -> Vehicle:
        return self.vehicles[vehicle_id]

    def ground_z(self, x: float, y: float) -> float:
        """The ground's height at (x, y): a station deck's top, else the terrain."""
        return self.ground.z_at(x, y)

    # ---- time -------------------------------------------------------------
    def step(self, dt_s: float) -> None:
        """Advance the world by ``dt_s`` simulated seconds."""
        if dt_s <= 0.0:
            return
        h = self.physics_step_s
        self._pending_s += dt_s
        n = math.floor(self._pending_s / h + 1e-9)
        self._pending_s = max(0.0, self._pending_s - n * h)
        for _ in range(n):
            self.time_s += h
            seen = len(self.safety.violations)
            for v in self.vehicles.values():
                before = v.state
                v.step(h, self.time_s)
                if v.state is not before:
                    self.safety.transition(v, before, self.time_s)
                    if v.state is FlightState.CRASHED:
                        self._log_track("crash", (v.id,))
            self.recorder.step(self.vehicles.values(), self.time_s)
            self.safety.check(self.vehicles.values(), self.workers, self.time_s)
            self._log_tracks(self.safety.violations[seen:])
            self.watch.step(self.vehicles.values(), self.workers, h)
            self._recharge(h)

    def _log_tracks(self, violations: list[Violation]) -> None:
        """Log how the two vehicles of each new separation violation came together."""
        for v in violations:
            if v.kind == SEPARATION:
                self._log_track(SEPARATION, (v.vehicle_id, v.detail.split()[0]))

    def _log_track(self, what: str, ids: tuple[str, ...]) -> None:
        """Log the flight recorder's last seconds of ``ids`` (a crash, a near miss)."""
        lines = "\n".join(self.recorder.track(ids))
        log.warning("%s %s at %.1f s, last seconds:\n%s", what, "/".join(ids), self.time_s, lines)

    def _recharge(self, dt_s: float) -> None:
        dock_r = self.rules.dock_radius_m
        for station in self.charging.values():
            docked = [
                v.id
                for v in self.vehicles.values()
                if v.state is FlightState.LANDED
                and not v.armed
                and any(
                    physics.horizontal_distance(v.position, p) <= dock_r
                    for p in self.spots[station.id]
                )
            ]
            if not docked and not station.on_pads and not station.queue:
                continue
            notices = station.update_docked(docked)
            batteries = {vid: self.vehicles[vid].battery for vid in docked}
            notices += station.step(dt_s, batteries)
            for vid, text in notices:
                self.vehicles[vid].say(Severity.INFO, text)

    def station_status(self, vehicle_id: str) -> tuple[str, str] | None:
        """(station id, "charging" | "charged" | "queued") for a docked vehicle."""
        for station in self.charging.values():
            status = station.status_of(vehicle_id)
            if status is not None:
                return station.id, status
        return None

    # ---- gripper (ToolHooks) ----------------------------------------------
    def grab(self, vehicle: Vehicle) -> str:
        """Take a tool from the nearest tool station in reach (nothing if it is empty)."""
        if vehicle.holding is not None:
            return f"Gripper: already holding {vehicle.holding.name}"
        landed = vehicle.state is FlightState.LANDED
        hovering = (
            vehicle.state is FlightState.FLYING
            and physics.speed(vehicle.velocity) <= self.rules.hover_speed_mps
        )
        station = None
        if landed or hovering:
            stations = list(self.tool_stations.values())
            station = station_in_reach(vehicle.position, stations, self.rules)
        tool = station.take() if station is not None else None
        if station is None or tool is None:
            return "Gripper: grabbed nothing"
        vehicle.holding = tool
        log.info("%s grabbed %s at %s", vehicle.id, tool.name, station.id)
        return f"Gripper: grabbed {tool.name} at {station.id}"

    def release(self, vehicle: Vehicle) -> str:
        tool, vehicle.holding = vehicle.holding, None
        if tool is None:
            return "Gripper: released nothing"
        pos = vehicle.position
        worker = worker_in_reach(pos, self.workers, self.rules)
        if worker is not None:
            self.deliveries.append(Delivery(tool.name, vehicle.id, worker, self.time_s, pos))
            log.info("%s delivered %s to %s", vehicle.id, tool.name, worker)
            return f"Gripper: delivered {tool.name} to {worker}"
        stations = list(self.tool_stations.values())
        station = station_in_reach(pos, stations, self.rules)
        if station is not None:
            station.put(tool)
        sid = station.id if station is not None else None
        self.drops.append(Drop(tool.name, vehicle.id, self.time_s, pos, sid))
        return f"Gripper: returned {tool.name} to {sid}" if sid else f"Gripper: dropped {tool.name}"

    # ---- faults -----------------------------------------------------------
    def move_worker(self, worker_id: str, position: Vec3) -> None:
        if worker_id not in self.workers:
            raise KeyError(worker_id)
        self.workers[worker_id] = position

    def fail_gripper(self, vehicle_id: str, failed: bool = True) -> None:
        self.vehicles[vehicle_id].gripper_failed = failed
