"""A sim_fleet world built from a proto scenario, so that the agent and the
simulator agree on the site (origin, stations, tools, workers) and the fleet."""

from __future__ import annotations

import msgspec

from proto.scenario import Scenario as ProtoScenario
from proto.site import BatterySwap
from sim_fleet import (
    Capability,
    GeoOrigin,
    RechargeModel,
    Scenario,
    StationSpec,
    ToolSpec,
    ToolStationSpec,
    VehicleSpec,
    VehicleType,
    WorkerSpec,
)


def _xyz(p) -> tuple[float, float, float]:
    return (p.x_m, p.y_m, p.z_m)


def sim_scenario(scenario: ProtoScenario, initial_soc: dict[str, float] | None = None) -> Scenario:
    """The simulator's view of ``scenario``."""
    soc = initial_soc or {}
    site, fleet = scenario.site, scenario.fleet
    types = {
        t.name: VehicleType(
            name=t.name,
            capabilities=frozenset(Capability(c) for c in t.capabilities),
            cruise_speed_mps=t.cruise_speed_mps,
            climb_rate_mps=t.climb_rate_mps,
            descent_rate_mps=t.climb_rate_mps,
            battery_wh=t.battery_wh,
            flight_w=t.flight_power_w,
            hover_w=t.hover_power_w,
            gripper=t.gripper,
        )
        for t in fleet.types
    }
    stations = tuple(
        StationSpec(
            id=s.id,
            position=_xyz(s.position),
            pads=s.pads,
            recharge=RechargeModel(kind="swap", swap_s=s.recharge.swap_s)
            if isinstance(s.recharge, BatterySwap)
            else RechargeModel(kind="charge", full_charge_s=s.recharge.full_charge_s),
        )
        for s in site.stations
    )
    return Scenario(
        site=site.id,
        origin=GeoOrigin(
            lat_deg=site.origin.lat_deg, lon_deg=site.origin.lon_deg, alt_m=site.origin.alt_m
        ),
        types=types,
        vehicles=tuple(
            VehicleSpec(
                id=u.id, type=u.type, home_station=u.home_station, initial_soc=soc.get(u.id, 1.0)
            )
            for u in fleet.uavs
        ),
        stations=stations,
        tool_stations=tuple(
            ToolStationSpec(
                id=ts.id,
                position=_xyz(ts.position),
                tools=tuple(ToolSpec(id=t.name, mass_kg=t.mass_kg) for t in ts.tools),
            )
            for ts in site.tool_stations
        ),
        workers=tuple(WorkerSpec(id=w.id, position=_xyz(w.position)) for w in site.workers),
    )


def write_json(scenario: ProtoScenario, path) -> str:
    """Write ``scenario`` as a JSON file the agent's ``--scenario`` reads."""
    path.write_bytes(msgspec.json.encode(scenario))
    return str(path)
