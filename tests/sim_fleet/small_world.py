"""A small world for simulator tests, shaped after the paper's (Calvo et al.,
ICUAS 2022); the paper scenario linecrew ships is ``linecrew.scenarios.load("paper")``.

Positions are the paper's; figures it left arbitrary are chosen here to be
plausible for small multirotors: a 60 Wh pack drawing ~250 W gives ~14 min of
flight (the paper's constant 0.4 %/s gave 4 min regardless of what the UAV did).
"""

from __future__ import annotations

from sim_fleet.scenario import (
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

_KINEMATICS = {"cruise_speed_mps": 1.6, "climb_rate_mps": 1.2, "descent_rate_mps": 1.2}
_POWER = {"battery_wh": 60.0, "flight_w": 250.0, "hover_w": 220.0}

TYPES = {
    "physical": VehicleType(
        name="physical",
        capabilities=frozenset({Capability.DELIVER, Capability.INSPECT}),
        gripper=True,
        **_KINEMATICS,
        **_POWER,
    ),
    "inspection": VehicleType(
        name="inspection",
        capabilities=frozenset({Capability.INSPECT, Capability.MONITOR}),
        **_KINEMATICS,
        **_POWER,
    ),
    "safety": VehicleType(
        name="safety",
        capabilities=frozenset({Capability.MONITOR}),
        **_KINEMATICS,
        **_POWER,
    ),
}

_CHARGE = RechargeModel(kind="charge", full_charge_s=1800.0)
_SWAP = RechargeModel(kind="swap", swap_s=60.0)

STATIONS = (
    StationSpec(id="C1", position=(-10.0, 10.0, 0.0), recharge=_SWAP),
    StationSpec(id="C2", position=(0.0, 20.0, 0.0), recharge=_CHARGE),
    StationSpec(id="C3", position=(10.0, 10.0, 0.0), recharge=_CHARGE),
    StationSpec(id="C4", position=(-10.0, 20.0, 0.0), recharge=_CHARGE),
    StationSpec(id="C5", position=(10.0, 20.0, 0.0), recharge=_CHARGE),
    StationSpec(id="H1", position=(-5.0, 5.0, 0.0)),
    StationSpec(id="H2", position=(0.0, 15.0, 0.0)),
    StationSpec(id="H3", position=(5.0, 10.0, 0.0)),
    StationSpec(id="H4", position=(-5.0, 20.0, 0.0)),
    StationSpec(id="H5", position=(5.0, 20.0, 0.0)),
)

_TOOLS = (
    ("hammer", 1.5, -2.0),
    ("wrench", 0.7, 1.0),
    ("allen_wrench", 0.05, 2.0),
    ("fixed_wrench", 0.15, 3.0),
    ("multimeter", 0.25, 4.0),
    ("pliers", 0.25, 5.0),
    ("tweezers", 0.2, 6.0),
)

TOOL_STATIONS = tuple(
    ToolStationSpec(id=f"P-{name}", position=(x, 5.0, 3.0), tools=(ToolSpec(id=name, mass_kg=kg),))
    for name, kg, x in _TOOLS
)

WORKERS = (
    WorkerSpec(id="W1", position=(0.0, 10.0, 3.0)),
    WorkerSpec(id="W2", position=(-5.0, 15.0, 3.0)),
    WorkerSpec(id="W3", position=(5.0, 20.0, 3.0)),
)

_ROLES = ("physical", "inspection", "safety", "safety", "safety")


def small_world(n_uavs: int = 3) -> Scenario:
    """UAV-1 physical (gripper), UAV-2 inspection, UAV-3.. safety; UAV-n on Cn."""
    if not 1 <= n_uavs <= 5:
        raise ValueError("the paper's world has room for 1 to 5 UAVs")
    vehicles = tuple(
        VehicleSpec(id=f"uav{i + 1}", type=_ROLES[i], home_station=f"C{i + 1}")
        for i in range(n_uavs)
    )
    return Scenario(
        site="paper",
        origin=GeoOrigin(lat_deg=37.4109, lon_deg=-6.0017, alt_m=10.0),
        types=dict(TYPES),
        vehicles=vehicles,
        stations=STATIONS,
        tool_stations=TOOL_STATIONS,
        workers=WORKERS,
    )
