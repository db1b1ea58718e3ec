"""The simulator's view of a site and its fleet: frozen value objects.

These are stand-ins until the shared site/fleet description lands in
``proto`` (``proto/site.py``). They carry only what the simulator needs and
use plain names with units, so swapping them for the proto types is a matter
of one adapter function (``Scenario`` <- proto site + fleet).

Geometry is site metres ``(east, north, up)`` around ``origin``, up being
the height above the origin's altitude (:mod:`linecrew.site_frame`); the
terrain is flat at ``up == 0`` and a station whose position has ``up > 0``
stands that high (a deck on a roof: see :mod:`sim_fleet.terrain`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum

Vec3 = tuple[float, float, float]


class Capability(StrEnum):
    """What a UAV type can be tasked with (system design section 4)."""

    INSPECT = "inspect"
    MONITOR = "monitor"
    DELIVER = "deliver"


@dataclass(frozen=True, kw_only=True)
class GeoOrigin:
    """Geodetic origin of the site's ENU frame (degrees, metres above WGS84)."""

    lat_deg: float
    lon_deg: float
    alt_m: float = 0.0


@dataclass(frozen=True, kw_only=True)
class VehicleType:
    """A UAV model: kinematic limits, battery and power figures."""

    name: str
    capabilities: frozenset[Capability]
    cruise_speed_mps: float  # default horizontal speed in GUIDED
    max_speed_mps: float = 0.0  # DO_CHANGE_SPEED cap; 0 means 2 x cruise
    climb_rate_mps: float = 1.5
    descent_rate_mps: float = 1.0
    land_speed_mps: float = 0.5  # final descent below land_final_alt_m (LAND_SPEED)
    accel_mps2: float = 2.0  # horizontal and vertical acceleration limit
    battery_wh: float = 100.0
    flight_w: float = 400.0  # drawn while moving
    hover_w: float = 350.0  # drawn while airborne and still
    cells: int = 4  # LiPo cells in series (voltage curve)
    gripper: bool = False

    @property
    def speed_cap_mps(self) -> float:
        return self.max_speed_mps or 2.0 * self.cruise_speed_mps


@dataclass(frozen=True, kw_only=True)
class RechargeModel:
    """How a station restores a battery.

    ``kind == "swap"``: the battery is full after ``swap_s`` whatever its level.
    ``kind == "charge"``: charging from empty to full takes ``full_charge_s``,
    so the time is proportional to the missing energy.
    """

    kind: str  # "swap" | "charge"
    swap_s: float = 60.0
    full_charge_s: float = 1800.0

    def __post_init__(self) -> None:
        if self.kind not in ("swap", "charge"):
            raise ValueError(f"unknown recharge kind {self.kind!r}")


@dataclass(frozen=True, kw_only=True)
class StationSpec:
    """A landing station; with ``recharge`` set, its ``pads`` recharge UAVs."""

    id: str
    position: Vec3
    pads: int = 1
    recharge: RechargeModel | None = None
    spots: tuple[Vec3, ...] = ()  # landing spots (proto.spots); none given: the position
    owners: tuple[str | None, ...] = ()  # whose home spot each spot is (None: shared)

    @property
    def spot_points(self) -> tuple[Vec3, ...]:
        """Where UAVs land at this station."""
        return self.spots or (self.position,)

    def home_spot(self, vehicle_id: str) -> Vec3:
        """Where ``vehicle_id`` starts: its own spot here, else the first."""
        points = self.spot_points
        if vehicle_id in self.owners:
            return points[self.owners.index(vehicle_id)]
        return points[0]


@dataclass(frozen=True, kw_only=True)
class ToolSpec:
    id: str
    mass_kg: float = 0.0


@dataclass(frozen=True, kw_only=True)
class ToolStationSpec:
    """A pick-up point holding tools at ``position``."""

    id: str
    position: Vec3
    tools: tuple[ToolSpec, ...] = ()


@dataclass(frozen=True, kw_only=True)
class WorkerSpec:
    id: str
    position: Vec3


@dataclass(frozen=True, kw_only=True)
class VehicleSpec:
    """One UAV of the fleet; it starts landed on its home station."""

    id: str
    type: str  # key into Scenario.types
    home_station: str
    initial_soc: float = 1.0  # state of charge at start, 0..1


@dataclass(frozen=True, kw_only=True)
class InteractionRules:
    """Distances that decide docking, grabbing and delivering (metres)."""

    dock_radius_m: float = 1.0  # horizontal, landed UAV to station
    grab_radius_m: float = 2.5  # horizontal, UAV to tool station
    grab_height_m: float = 2.5  # max height above the tool station to grab
    delivery_radius_m: float = 2.5  # horizontal, UAV to worker at release
    delivery_height_m: float = 3.5  # max |dz| UAV to worker at release
    hover_speed_mps: float = 0.5  # below this a flying UAV counts as hovering
    watch_radius_m: float = 15.0  # horizontal, hovering UAV to the worker it watches


@dataclass(frozen=True, kw_only=True)
class SafetyRules:
    """Distances the simulator watches for violations (metres, 3-D); the
    defaults are ``proto.Safety``'s."""

    people_clearance_m: float = 1.5  # no airborne UAV closer to a worker
    separation_m: float = 1.0  # no two airborne UAVs closer to each other


@dataclass(frozen=True, kw_only=True)
class Scenario:
    """Everything the simulator needs to build a world."""

    site: str = "default"
    origin: GeoOrigin
    types: dict[str, VehicleType]
    vehicles: tuple[VehicleSpec, ...]
    stations: tuple[StationSpec, ...]
    tool_stations: tuple[ToolStationSpec, ...] = ()
    workers: tuple[WorkerSpec, ...] = ()
    rules: InteractionRules = field(default_factory=InteractionRules)
    safety: SafetyRules = field(default_factory=SafetyRules)

    def __post_init__(self) -> None:
        station_ids = {s.id for s in self.stations}
        for v in self.vehicles:
            if v.type not in self.types:
                raise ValueError(f"vehicle {v.id}: unknown type {v.type!r}")
            if v.home_station not in station_ids:
                raise ValueError(f"vehicle {v.id}: unknown home station {v.home_station!r}")
        if len({v.id for v in self.vehicles}) != len(self.vehicles):
            raise ValueError("duplicate vehicle ids")

    def station(self, station_id: str) -> StationSpec:
        return next(s for s in self.stations if s.id == station_id)
