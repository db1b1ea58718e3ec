from __future__ import annotations

import proto
from sim_fleet import World
from sim_fleet.from_proto import scenario_from_proto


def test_proto_site_and_fleet_become_a_world():
    site = proto.Site(
        id="s1",
        origin=proto.GeoPoint(lat_deg=37.4, lon_deg=-6.0, alt_m=5.0),
        stations=[
            proto.ChargingStation(
                id="C1",
                position=proto.Point(x_m=1.0, y_m=2.0),
                pads=2,
                recharge=proto.BatterySwap(swap_s=42.0),
            ),
            proto.ChargingStation(id="C2", position=proto.Point(x_m=9.0, y_m=2.0)),
        ],
        tool_stations=[
            proto.ToolStation(
                id="T1",
                position=proto.Point(x_m=3.0, y_m=3.0, z_m=3.0),
                tools=[proto.Tool(name="hammer", mass_kg=1.5)],
            )
        ],
        workers=[proto.Worker(id="W1", position=proto.Point(x_m=0.0, y_m=10.0, z_m=3.0))],
    )
    fleet = proto.Fleet(
        types=[
            proto.UavType(
                name="carrier",
                capabilities={proto.Capability.DELIVER: 0.0},
                battery_wh=80.0,
                flight_power_w=300.0,
                hover_power_w=250.0,
                gripper=True,
            )
        ],
        uavs=[proto.UavSpec(id="uav1", type="carrier", home_station="C1")],
    )
    sc = scenario_from_proto(site, fleet)
    assert sc.site == "s1" and sc.origin.alt_m == 5.0
    assert sc.station("C1").recharge.kind == "swap" and sc.station("C1").recharge.swap_s == 42.0
    assert sc.station("C2").recharge.kind == "charge"
    w = World(sc)
    v = w.vehicle("uav1")
    assert v.home == (1.0, 2.0, 0.0) and v.has_gripper and v.battery.capacity_wh == 80.0
    assert w.tool_stations["T1"].tools[0].id == "hammer"
