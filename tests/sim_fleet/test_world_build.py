"""A world built from a shared proto scenario: spots, homes, types, safety, tools."""

from __future__ import annotations

import pytest

import proto
from sim_fleet import World


def _scenario(site: proto.Site, fleet: proto.Fleet) -> proto.Scenario:
    return proto.Scenario(name="t", site=site, fleet=fleet)


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
    w = World(_scenario(site, fleet))
    v = w.vehicle("uav1")
    # one spot per pad about the station, uav1's home spot on along the row, 2 m apart
    assert w.spots["C1"] == ((4.0, 2.0, 0.0), (0.0, 2.0, 0.0), (2.0, 2.0, 0.0))
    assert w.spot_owners["C1"] == ("uav1", None, None)
    assert v.home == (4.0, 2.0, 0.0) and v.has_gripper and v.battery.capacity_wh == 80.0
    assert v.descent_mps == v.climb_mps  # proto has one vertical rate
    assert w.workers == {"W1": (0.0, 10.0, 3.0)}
    assert w.tool_stations["T1"].position == (3.0, 3.0, 3.0)
    assert w.tool_stations["T1"].tools[0].name == "hammer"


def _site(**kw) -> proto.Site:
    return proto.Site(
        origin=proto.GeoPoint(lat_deg=37.4, lon_deg=-6.0),
        stations=[proto.ChargingStation(id="C1", position=proto.Point(x_m=0.0, y_m=0.0))],
        **kw,
    )


_FLEET = proto.Fleet(
    types=[proto.UavType(name="q", capabilities={proto.Capability.INSPECT: 0.0})],
    uavs=[proto.UavSpec(id="uav1", type="q", home_station="C1")],
)


def test_the_simulators_ground_is_at_zero():
    with pytest.raises(ValueError, match="ground"):
        World(_scenario(_site(safety=proto.Safety(ground_z_m=5.0)), _FLEET))


def test_tool_count_gives_the_station_that_many_copies():
    tools = [proto.Tool(name="hammer", mass_kg=1.5, count=3), proto.Tool(name="pliers")]
    station = proto.ToolStation(id="T1", position=proto.Point(x_m=3.0, y_m=3.0), tools=tools)
    w = World(_scenario(_site(tool_stations=[station]), _FLEET))
    held = [t.name for t in w.tool_stations["T1"].tools]
    assert held == ["hammer"] * 3 + ["pliers"]
    assert held.count("hammer") == station.stock("hammer")
    assert w.tool_stations["T1"].tools[0].mass_kg == 1.5
