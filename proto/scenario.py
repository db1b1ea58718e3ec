"""A scenario: the site, the fleet, and actions scripted to be submitted at
given times. The one document that the ground station, the simulator, the
agents and ``linecrew up`` / ``demo`` all load (YAML or JSON)."""

from __future__ import annotations

from proto.base import Id, Message, NonNegative, Record, Text
from proto.fleet import Fleet
from proto.mission import Action
from proto.site import Site


class ScriptedAction(Record, frozen=True, kw_only=True):
    """``action`` submitted ``at_s`` seconds after the mission starts."""

    id: Id
    at_s: NonNegative = 0.0
    action: Action


class Scenario(Message, frozen=True, kw_only=True):
    """Everything needed to run a mission, simulated or real."""

    name: Id
    description: Text = ""
    site: Site
    fleet: Fleet
    actions: list[ScriptedAction] = []
