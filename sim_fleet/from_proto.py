"""Build the simulator's ``Scenario`` from the shared ``proto`` site and fleet.

The simulator keeps its own small value types (``scenario``) for what proto
does not describe (descent rate, initial charge, interaction distances); this
adapter is the single place that knows both, so proto can evolve freely.
"""

from __future__ import annotations

import proto
from sim_fleet.scenario import (
    Capability,
    GeoOrigin,
    InteractionRules,
    RechargeModel,
    SafetyRules,
    Scenario,
    StationSpec,
    ToolSpec,
    ToolStationSpec,
    Vec3,
    VehicleSpec,
    VehicleType,
    WorkerSpec,
)


def _vec(p: proto.Point) -> Vec3:
    return (p.x_m, p.y_m, p.z_m)


def _recharge(model: proto.RechargeModel) -> RechargeModel:
    if isinstance(model, proto.BatterySwap):
        return RechargeModel(kind="swap", swap_s=model.swap_s)
    return RechargeModel(kind="charge", full_charge_s=model.full_charge_s)


def _safety(s: proto.Safety) -> SafetyRules:
    if s.ground_z_m != 0.0:
        raise ValueError(f"the simulator's ground is at z = 0, not {s.ground_z_m}")
    return SafetyRules(people_clearance_m=s.people_clearance_m, separation_m=s.separation_m)


def _tools(t: proto.ToolStation) -> tuple[ToolSpec, ...]:
    """``count`` copies of each tool."""
    return tuple(
        ToolSpec(id=tool.name, mass_kg=tool.mass_kg) for tool in t.tools for _ in range(tool.count)
    )


def _vehicle_type(t: proto.UavType) -> VehicleType:
    return VehicleType(
        name=t.name,
        capabilities=frozenset(Capability(c.value) for c in t.capabilities),
        cruise_speed_mps=t.cruise_speed_mps,
        climb_rate_mps=t.climb_rate_mps,
        descent_rate_mps=t.climb_rate_mps,  # proto has one vertical rate
        battery_wh=t.battery_wh,
        flight_w=t.flight_power_w,
        hover_w=t.hover_power_w,
        gripper=t.gripper,
    )


def scenario_from_proto(
    site: proto.Site,
    fleet: proto.Fleet,
    *,
    initial_soc: float = 1.0,
    rules: InteractionRules | None = None,
) -> Scenario:
    """The scenario for ``site`` and ``fleet``; every UAV starts full on its home pad."""
    return Scenario(
        site=site.id,
        origin=GeoOrigin(
            lat_deg=site.origin.lat_deg, lon_deg=site.origin.lon_deg, alt_m=site.origin.alt_m
        ),
        types={t.name: _vehicle_type(t) for t in fleet.types},
        vehicles=tuple(
            VehicleSpec(id=u.id, type=u.type, home_station=u.home_station, initial_soc=initial_soc)
            for u in fleet.uavs
        ),
        stations=tuple(
            StationSpec(
                id=s.id,
                position=_vec(s.position),
                pads=s.pads,
                recharge=_recharge(s.recharge),
                spots=tuple(_vec(p) for p in proto.spot_positions(s, fleet)),
                owners=tuple(proto.spot_owners(s, fleet)),
            )
            for s in site.stations
        ),
        tool_stations=tuple(
            ToolStationSpec(id=t.id, position=_vec(t.position), tools=_tools(t))
            for t in site.tool_stations
        ),
        workers=tuple(WorkerSpec(id=w.id, position=_vec(w.position)) for w in site.workers),
        rules=rules or InteractionRules(),
        safety=_safety(site.safety),
    )
