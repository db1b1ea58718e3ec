"""Small builders and a hand-driven clock for sim_fleet unit tests."""

from __future__ import annotations

from collections.abc import Callable

from sim_fleet import (
    GeoOrigin,
    InteractionRules,
    RechargeModel,
    Scenario,
    StationSpec,
    ToolSpec,
    ToolStationSpec,
    VehicleSpec,
    VehicleType,
    WorkerSpec,
    World,
)
from sim_fleet import autopilot as ap
from sim_fleet.autopilot import Command
from sim_fleet.events import Outcome
from sim_fleet.modes import Mode
from sim_fleet.vehicle import AutopilotParams, Vehicle

QUAD = VehicleType(
    name="quad",
    capabilities=frozenset(),
    cruise_speed_mps=5.0,
    climb_rate_mps=2.0,
    descent_rate_mps=1.5,
    accel_mps2=3.0,
    battery_wh=100.0,
    flight_w=360.0,
    hover_w=300.0,
)
CARRIER = VehicleType(
    name="carrier",
    capabilities=frozenset(),
    cruise_speed_mps=5.0,
    climb_rate_mps=2.0,
    descent_rate_mps=1.5,
    battery_wh=100.0,
    flight_w=360.0,
    hover_w=300.0,
    gripper=True,
)


def scenario(
    *,
    n: int = 1,
    vtype: VehicleType = QUAD,
    stations: tuple[StationSpec, ...] | None = None,
    homes: tuple[str, ...] | None = None,
    soc: float = 1.0,
) -> Scenario:
    stations = stations or (
        StationSpec(
            id="S1",
            position=(0.0, 0.0, 0.0),
            pads=1,
            recharge=RechargeModel(kind="charge", full_charge_s=1000.0),
        ),
        StationSpec(
            id="S2",
            position=(100.0, 0.0, 0.0),
            pads=1,
            recharge=RechargeModel(kind="swap", swap_s=30.0),
        ),
        StationSpec(id="L1", position=(0.0, 50.0, 0.0)),
    )
    homes = homes or tuple("L1" for _ in range(n))
    return Scenario(
        origin=GeoOrigin(lat_deg=37.41, lon_deg=-6.0, alt_m=10.0),
        types={vtype.name: vtype},
        vehicles=tuple(
            VehicleSpec(id=f"u{i + 1}", type=vtype.name, home_station=homes[i], initial_soc=soc)
            for i in range(n)
        ),
        stations=stations,
        tool_stations=(
            ToolStationSpec(
                id="T1", position=(20.0, 0.0, 3.0), tools=(ToolSpec(id="hammer", mass_kg=1.5),)
            ),
        ),
        workers=(WorkerSpec(id="W1", position=(40.0, 0.0, 3.0)),),
        rules=InteractionRules(),
    )


def world(**kw) -> World:
    params = kw.pop("params", AutopilotParams(auto_disarm_s=None, warmup_s=0.0))
    return World(scenario(**kw), params=params)


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
