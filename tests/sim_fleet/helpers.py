"""Small builders and a hand-driven clock for sim_fleet unit tests."""

from __future__ import annotations

from collections.abc import Callable

import msgspec

from proto.fleet import Fleet, UavSpec, UavType
from proto.geo import GeoPoint, Point
from proto.scenario import Scenario
from proto.site import BatterySwap, Charging, ChargingStation, Site, Tool, ToolStation, Worker
from sim_fleet import World
from sim_fleet import autopilot as ap
from sim_fleet.autopilot import Command
from sim_fleet.events import Outcome
from sim_fleet.modes import Mode
from sim_fleet.params import AutopilotParams
from sim_fleet.vehicle import Vehicle

QUAD = UavType(
    name="quad",
    capabilities={},
    cruise_speed_mps=5.0,
    climb_rate_mps=2.0,
    battery_wh=100.0,
    flight_power_w=360.0,
    hover_power_w=300.0,
)
CARRIER = msgspec.structs.replace(QUAD, name="carrier", gripper=True)


def station(station_id: str, x: float, y: float, z: float = 0.0, **kw) -> ChargingStation:
    """A charging station at (x, y, z); ``kw``: pads, recharge."""
    return ChargingStation(id=station_id, position=Point(x_m=x, y_m=y, z_m=z), **kw)


def scenario(
    *,
    n: int = 1,
    vtype: UavType = QUAD,
    stations: tuple[ChargingStation, ...] | None = None,
    homes: tuple[str, ...] | None = None,
) -> Scenario:
    stations = stations or (
        station("S1", 0.0, 0.0, recharge=Charging(full_charge_s=1000.0)),
        station("S2", 100.0, 0.0, recharge=BatterySwap(swap_s=30.0)),
        station("L1", -2.0, 50.0),  # its pad; u1's home spot is (0, 50, 0), u2's (2, 50, 0)...
    )
    homes = homes or tuple("L1" for _ in range(n))
    site = Site(
        origin=GeoPoint(lat_deg=37.41, lon_deg=-6.0, alt_m=10.0),
        stations=list(stations),
        tool_stations=[
            ToolStation(
                id="T1",
                position=Point(x_m=20.0, y_m=0.0, z_m=3.0),
                tools=[Tool(name="hammer", mass_kg=1.5)],
            )
        ],
        workers=[Worker(id="W1", position=Point(x_m=40.0, y_m=0.0, z_m=3.0))],
    )
    uavs = [UavSpec(id=f"u{i + 1}", type=vtype.name, home_station=homes[i]) for i in range(n)]
    return Scenario(name="test", site=site, fleet=Fleet(types=[vtype], uavs=uavs))


def world(*, soc: float = 1.0, **kw) -> World:
    """A world of :func:`scenario` (``kw``), every battery at ``soc``."""
    params = kw.pop("params", AutopilotParams(auto_disarm_s=None, warmup_s=0.0))
    w = World(scenario(**kw), params=params)
    for v in w.vehicles.values():
        v.set_battery_soc(soc)
    return w


def command(w: World, v: Vehicle, cmd: int, *params: float, frame: int | None = None) -> Outcome:
    p = tuple(float(x) for x in params) + (0.0,) * (7 - len(params))
    return ap.handle_command(Command(cmd, p, frame), v, w)  # type: ignore[arg-type]


def run_until(
    w: World, pred: Callable[[], bool], *, max_s: float = 600.0, dt: float = 0.1
) -> float:
    """Step the world by hand until ``pred()``; returns the simulated seconds it took."""
    t0 = w.time_s
    while not pred():
        if w.time_s - t0 > max_s:
            raise AssertionError(f"condition not met within {max_s} simulated s")
        w.step(dt)
    return w.time_s - t0


def airborne(w: World, v: Vehicle, alt_m: float = 10.0) -> None:
    """GUIDED, arm, take off and wait until hovering ``alt_m`` above home."""
    assert command(w, v, 176, 1, Mode.GUIDED).result == 0
    assert command(w, v, 400, 1).result == 0
    assert command(w, v, 22, 0, 0, 0, 0, 0, 0, alt_m).result == 0
    z = v.home[2] + alt_m
    run_until(w, lambda: v.state == "flying" and abs(v.position[2] - z) < 1e-6)
