"""sim_fleet: simulated multirotors, each a MAVLink endpoint like ArduCopter SITL.

Public API (import from here):

- ``World``: vehicles, charging stations, tool stations, workers, built from
  the shared ``proto.scenario.Scenario``; ``step(dt_s)`` on an injected clock;
  fault operations; ``deliveries`` and ``violations`` (ground truth, see
  ``safety``). ``InteractionRules`` (``rules``) are the simulator's own
  docking, grabbing, delivery and watch distances.
- ``Fleet`` / ``FleetConfig`` / ``FleetThread``: the runner that owns the world
  and one UDP MAVLink endpoint per vehicle (vehicle i on ``base_port + i``).
"""

from sim_fleet.autopilot import Command
from sim_fleet.battery import Battery
from sim_fleet.events import Outcome, Result, Severity, StatusText
from sim_fleet.fleet import Fleet, FleetConfig, FleetThread
from sim_fleet.geo import GeoFrame
from sim_fleet.modes import FlightState, Mode
from sim_fleet.params import AutopilotParams
from sim_fleet.rules import InteractionRules
from sim_fleet.safety import Violation
from sim_fleet.streams import TelemetryRates
from sim_fleet.tools import Delivery, Drop
from sim_fleet.vehicle import Vehicle
from sim_fleet.world import World

__all__ = [
    "AutopilotParams",
    "Battery",
    "Command",
    "Delivery",
    "Drop",
    "Fleet",
    "FleetConfig",
    "FleetThread",
    "FlightState",
    "GeoFrame",
    "InteractionRules",
    "Mode",
    "Outcome",
    "Result",
    "Severity",
    "StatusText",
    "TelemetryRates",
    "Vehicle",
    "Violation",
    "World",
]
