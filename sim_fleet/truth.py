"""The simulator's ground truth as a wire message (for tests and tools)."""

from __future__ import annotations

from proto.geo import Point
from proto.sim import DeliveryRecord, SimState, VehicleTruth
from sim_fleet.world import World


def sim_state(world: World, speedup: float) -> SimState:
    """Vehicles and deliveries of ``world`` now."""
    vehicles = []
    for vehicle in world.vehicles.values():
        docked = world.station_status(vehicle.id)
        x, y, z = vehicle.position
        vehicles.append(
            VehicleTruth(
                uav_id=vehicle.id,
                position=Point(x_m=x, y_m=y, z_m=z),
                battery_fraction=min(1.0, max(0.0, vehicle.battery.soc)),
                state=str(vehicle.state.name).lower(),
                armed=vehicle.armed,
                tool=vehicle.holding.id if vehicle.holding else None,
                docked_at=docked[0] if docked else None,
            )
        )
    deliveries = [
        DeliveryRecord(
            tool=d.tool_id, uav_id=d.vehicle_id, worker_id=d.worker_id, sim_time_s=d.time_s
        )
        for d in world.deliveries
    ]
    return SimState(
        sim_time_s=world.time_s, speedup=speedup, vehicles=vehicles, deliveries=deliveries
    )
