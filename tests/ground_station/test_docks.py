"""Where landed UAVs sit: a UAV on its home spot is at home, also where the
rows of spots of two stations cross (the paper site resized to 100 UAVs)."""

from __future__ import annotations

import msgspec

from ground_station.fleet_monitor import FleetMonitor
from ground_station.fleet_state import Docks, drop_done_home
from linecrew_runtime.scenarios import load, with_fleet_size
from proto import FlightState, GeoPoint, GoHomeTask, Telemetry
from proto.spots import spot_owners, spot_positions


def test_a_uav_on_its_home_spot_is_home_where_two_stations_spots_cross():
    scenario = with_fleet_size(load("paper"), 100)
    c1, c3 = scenario.site.station("C1"), scenario.site.station("C3")
    spot = spot_positions(c3, scenario.fleet)[spot_owners(c3, scenario.fleet).index("uav-05")]
    assert any(
        abs(spot.x_m - q.x_m) < 0.5 and abs(spot.y_m - q.y_m) < 0.5
        for q in spot_positions(c1, scenario.fleet)
    )  # the geometry this guards: a spot of C3 is also one of C1
    sample = Telemetry(
        uav_id="uav-05",
        stamp_s=0.0,
        position=spot,
        geo=GeoPoint(),
        battery_wh=50.0,
        battery_fraction=0.5,
        flight_state=FlightState.LANDED,
    )
    docks = Docks(scenario)
    assert docks.under(sample, "C3").id == "C3"
    assert docks.under(sample, "C1").id == "C1"
    monitor = FleetMonitor([u.id for u in scenario.fleet.uavs], 5.0)
    monitor.on_telemetry(sample, 0.0)
    home = GoHomeTask(task_id="uav-05.home", station_id="C3", position=c3.position)
    assert drop_done_home(docks, monitor, "uav-05", [home]) == []  # nothing to do: not re-sent
    flying = msgspec.structs.replace(sample, flight_state=FlightState.FLYING)
    monitor.on_telemetry(flying, 0.1)
    assert drop_done_home(docks, monitor, "uav-05", [home]) == [home]
