"""The simulator's own interaction rules: the distances at which it docks,
grabs, delivers and credits watching. They are how the simulated world
judges contact, not part of the wire scenario (:mod:`proto.scenario`)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, kw_only=True)
class InteractionRules:
    """Distances that decide docking, grabbing and delivering (metres)."""

    dock_radius_m: float = 1.0  # horizontal, landed UAV to station
    grab_radius_m: float = 2.5  # horizontal, UAV to tool station
    grab_height_m: float = 2.5  # max height above the tool station to grab
    delivery_radius_m: float = 2.5  # horizontal, UAV to worker at release
    delivery_height_m: float = 3.5  # max |dz| UAV to worker at release
    hover_speed_mps: float = 0.5  # below this a flying UAV counts as hovering
    watch_radius_m: float = 15.0  # horizontal, hovering UAV to the worker it watches
