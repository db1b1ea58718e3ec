"""sim_fleet: simulated multirotors, each a MAVLink endpoint like ArduCopter SITL.

Public API (import from here):

- ``Scenario`` and its parts (``scenario``): the site and fleet to simulate;
  ``scenario_from_proto()`` builds one from a shared ``proto`` site and fleet.
- ``World``: vehicles, charging stations, tool stations, workers; ``step(dt_s)``
  on an injected clock; fault operations; ``deliveries`` and ``violations``
  (ground truth, see ``safety``).
- ``Fleet`` / ``FleetConfig`` / ``FleetThread``: the runner that owns the world
  and one UDP MAVLink endpoint per vehicle (vehicle i on ``base_port + i``).
"""

from sim_fleet.autopilot import Command
from sim_fleet.battery import Battery
from sim_fleet.events import Outcome, Result, Severity, StatusText
from sim_fleet.fleet import Fleet, FleetConfig, FleetThread
from sim_fleet.from_proto import scenario_from_proto
from sim_fleet.geo import GeoFrame
from sim_fleet.modes import FlightState, Mode
from sim_fleet.safety import Violation
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
    VehicleSpec,
    VehicleType,
    WorkerSpec,
)
from sim_fleet.streams import TelemetryRates
from sim_fleet.tools import Delivery, Drop
from sim_fleet.vehicle import AutopilotParams, Vehicle
from sim_fleet.world import World

__all__ = [
    "AutopilotParams",
    "Battery",
    "Capability",
    "Command",
    "Delivery",
    "Drop",
    "Fleet",
    "FleetConfig",
    "FleetThread",
    "FlightState",
    "GeoFrame",
    "GeoOrigin",
    "InteractionRules",
    "Mode",
    "Outcome",
    "RechargeModel",
    "Result",
    "SafetyRules",
    "Scenario",
    "Severity",
    "StationSpec",
    "StatusText",
    "TelemetryRates",
    "ToolSpec",
    "ToolStationSpec",
    "Vehicle",
    "VehicleSpec",
    "VehicleType",
    "Violation",
    "WorkerSpec",
    "World",
    "scenario_from_proto",
]
