"""The fleet description: UAV types (capabilities, speed, battery, power)
and the UAVs themselves. Shared by the ground station, agents and simulator.
"""

from __future__ import annotations

import enum

from proto.base import Fraction, Id, Message, NonNegative, Positive, Record


class Capability(enum.StrEnum):
    """What a UAV type can do."""

    INSPECT = "inspect"
    MONITOR = "monitor"
    DELIVER = "deliver"


class UavType(Record, frozen=True, kw_only=True):
    """A model of UAV.

    ``capabilities`` maps each capability to its suitability cost (the
    paper's J1): 0.0 ideal, up to 1.0 barely acceptable; a missing capability
    means incapable.
    """

    name: Id
    capabilities: dict[Capability, Fraction]
    cruise_speed_mps: Positive = 5.0
    climb_rate_mps: Positive = 2.0
    battery_wh: Positive = 100.0
    flight_power_w: NonNegative = 300.0
    hover_power_w: NonNegative = 250.0
    gripper: bool = False


class MissionEnd(enum.StrEnum):
    """Where the UAVs end the mission (the planner's ``Problem.end``)."""

    HOME = "home"
    """Each on its home station (the paper's "back to station")."""
    ANY_STATION = "any_station"
    """On any station with a pad free from the landing on."""


class UavSpec(Record, frozen=True, kw_only=True):
    """One UAV of the fleet, by type, with the station it starts on."""

    id: Id
    type: Id
    home_station: Id


class Fleet(Message, frozen=True, kw_only=True):
    """The UAV types and UAVs of a deployment."""

    types: list[UavType]
    uavs: list[UavSpec]
    reserve_fraction: Fraction = 0.2
    end: MissionEnd = MissionEnd.HOME
    """Where the UAVs end the mission, with as many recharges as needed."""

    def type_of(self, uav_id: str) -> UavType | None:
        """The type of the UAV with this id, if both exist."""
        spec = next((u for u in self.uavs if u.id == uav_id), None)
        if spec is None:
            return None
        return next((t for t in self.types if t.name == spec.type), None)
