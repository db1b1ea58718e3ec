"""A small world for simulator tests, shaped after the paper's (Calvo et al.,
ICUAS 2022); the paper scenario linecrew ships is ``linecrew_runtime.scenarios.load("paper")``.

Positions are the paper's; figures it left arbitrary are chosen here to be
plausible for small multirotors: a 60 Wh pack drawing ~250 W gives ~14 min of
flight (the paper's constant 0.4 %/s gave 4 min regardless of what the UAV did).
"""

from __future__ import annotations

from proto.fleet import Capability, Fleet, UavSpec, UavType
from proto.geo import GeoPoint, Point
from proto.scenario import Scenario
from proto.site import BatterySwap, Charging, ChargingStation, Site, Tool, ToolStation, Worker

_FIGURES = {
    "cruise_speed_mps": 1.6,
    "climb_rate_mps": 1.2,
    "battery_wh": 60.0,
    "flight_power_w": 250.0,
    "hover_power_w": 220.0,
}

TYPES = [
    UavType(
        name="physical",
        capabilities={Capability.DELIVER: 0.0, Capability.INSPECT: 0.0},
        gripper=True,
        **_FIGURES,
    ),
    UavType(
        name="inspection",
        capabilities={Capability.INSPECT: 0.0, Capability.MONITOR: 0.0},
        **_FIGURES,
    ),
    UavType(name="safety", capabilities={Capability.MONITOR: 0.0}, **_FIGURES),
]

_CHARGE = Charging(full_charge_s=1800.0)
_SWAP = BatterySwap(swap_s=60.0)


def _at(x: float, y: float, z: float = 0.0) -> Point:
    return Point(x_m=x, y_m=y, z_m=z)


STATIONS = [
    ChargingStation(id="C1", position=_at(-10.0, 10.0), recharge=_SWAP),
    ChargingStation(id="C2", position=_at(0.0, 20.0), recharge=_CHARGE),
    ChargingStation(id="C3", position=_at(10.0, 10.0), recharge=_CHARGE),
    ChargingStation(id="C4", position=_at(-10.0, 20.0), recharge=_CHARGE),
    ChargingStation(id="C5", position=_at(10.0, 20.0), recharge=_CHARGE),
    *(
        ChargingStation(id=f"H{i + 1}", position=_at(x, y))
        for i, (x, y) in enumerate(
            ((-5.0, 5.0), (0.0, 15.0), (5.0, 10.0), (-5.0, 20.0), (5.0, 20.0))
        )
    ),
]

_TOOLS = (
    ("hammer", 1.5, -2.0),
    ("wrench", 0.7, 1.0),
    ("allen_wrench", 0.05, 2.0),
    ("fixed_wrench", 0.15, 3.0),
    ("multimeter", 0.25, 4.0),
    ("pliers", 0.25, 5.0),
    ("tweezers", 0.2, 6.0),
)

TOOL_STATIONS = [
    ToolStation(id=f"P-{name}", position=_at(x, 5.0, 3.0), tools=[Tool(name=name, mass_kg=kg)])
    for name, kg, x in _TOOLS
]

WORKERS = [
    Worker(id="W1", position=_at(0.0, 10.0, 3.0)),
    Worker(id="W2", position=_at(-5.0, 15.0, 3.0)),
    Worker(id="W3", position=_at(5.0, 20.0, 3.0)),
]

_ROLES = ("physical", "inspection", "safety", "safety", "safety")


def small_world(n_uavs: int = 3) -> Scenario:
    """UAV-1 physical (gripper), UAV-2 inspection, UAV-3.. safety; UAV-n on Cn."""
    if not 1 <= n_uavs <= 5:
        raise ValueError("the paper's world has room for 1 to 5 UAVs")
    uavs = [
        UavSpec(id=f"uav{i + 1}", type=_ROLES[i], home_station=f"C{i + 1}") for i in range(n_uavs)
    ]
    site = Site(
        id="paper",
        origin=GeoPoint(lat_deg=37.4109, lon_deg=-6.0017, alt_m=10.0),
        stations=STATIONS,
        tool_stations=TOOL_STATIONS,
        workers=WORKERS,
    )
    return Scenario(name="small", site=site, fleet=Fleet(types=TYPES, uavs=uavs))
