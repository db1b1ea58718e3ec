"""The simulator's ground truth as a wire message (for tests and tools)."""

from __future__ import annotations

from proto.sim import DeliveryRecord, SafetyViolation, SimState, VehicleTruth, WatchRecord
from sim_fleet.geo import point
from sim_fleet.world import World


def sim_state(world: World, speedup: float) -> SimState:
    """Vehicles, deliveries, safety violations and watched seconds of ``world`` now."""
    vehicles = []
    for vehicle in world.vehicles.values():
        docked = world.station_status(vehicle.id)
        vehicles.append(
            VehicleTruth(
                uav_id=vehicle.id,
                position=point(vehicle.position),
                battery_fraction=min(1.0, max(0.0, vehicle.battery.soc)),
                state=str(vehicle.state.name).lower(),
                armed=vehicle.armed,
                tool=vehicle.holding.name if vehicle.holding else None,
                docked_at=docked[0] if docked else None,
            )
        )
    deliveries = [
        DeliveryRecord(
            tool=d.tool_id, uav_id=d.vehicle_id, worker_id=d.worker_id, sim_time_s=d.time_s
        )
        for d in world.deliveries
    ]
    violations = [
        SafetyViolation(
            kind=v.kind,
            uav_id=v.vehicle_id,
            sim_time_s=v.time_s,
            position=point(v.position),
            detail=v.detail,
        )
        for v in world.violations
    ]
    return SimState(
        sim_time_s=world.time_s,
        speedup=speedup,
        vehicles=vehicles,
        deliveries=deliveries,
        violations=violations,
        watched=[
            WatchRecord(worker_id=w, uav_id=u, seconds=s)
            for (w, u), s in sorted(world.watch.seconds.items())
        ],
    )
