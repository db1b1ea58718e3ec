"""Landing spots at charging stations, and which UAV may land on which.

A charging station is a row of landing spots along +x, ``SPOT_SPACING_M``
apart: one spot per pad that any UAV may use, centred on its position, and
a home spot for each UAV whose home it is (in fleet order; the simulator
starts each UAV on its own), on along the row (at least one spot in all;
spot indices list the home spots first). At
most ``pads`` of the docked UAVs charge at once. A home spot is its
owner's alone: so a UAV cut off from every controller can always land at
home without meeting another. No spot takes two UAVs: the station's
controller (the simulator plays it) grants each spot to one UAV at a time.
A UAV claims a free spot with a :class:`SpotClaim` on ``uav/{id}/spot``
and lands only on a spot that :class:`StationSpots` (on
``station/{id}/spots``) shows granted to it; until then it holds clear of
the station. A grant ends when its UAV takes off from the spot, claims
another, releases it (``station_id`` None) or has not landed within the
controller's time limit.
"""

from __future__ import annotations

from proto.base import Count, Finite, Id, Message
from proto.fleet import Fleet
from proto.geo import Point
from proto.site import ChargingStation

SPOT_SPACING_M = 2.0
"""Metres between the centres of two neighbouring spots."""


def spot_owners(station: ChargingStation, fleet: Fleet) -> list[str | None]:
    """Whose spot each spot of ``station`` is, spot 0 first: the home spots
    of the UAVs based there, then one shared spot (None) per pad."""
    homes = [u.id for u in fleet.uavs if u.home_station == station.id]
    return [*homes, *[None] * max(station.pads, 0 if homes else 1)]


def spot_positions(station: ChargingStation, fleet: Fleet) -> list[Point]:
    """Where the spots of ``station`` are, spot 0 first: the shared spots
    (its pads) centred on its position, the home spots on after them along
    +x (centred themselves if there is no pad). A point the site puts just
    beside the station (the paper's inspection waypoint 1 m from C2) keeps
    its distance from the pads whatever the fleet."""
    owners = spot_owners(station, fleet)
    shared = owners.count(None)
    homes = len(owners) - shared
    first = -(shared - 1) / 2 if shared else -(homes - 1) / 2
    slots = [first + shared + i for i in range(homes)] + [first + i for i in range(shared)]
    p = station.position
    return [Point(x_m=p.x_m + slot * SPOT_SPACING_M, y_m=p.y_m, z_m=p.z_m) for slot in slots]


class SpotClaim(Message, frozen=True, kw_only=True):
    """A UAV asks for ``spot`` of ``station_id`` (None: gives up its claim)."""

    uav_id: Id
    station_id: Id | None = None
    spot: Count = 0
    stamp_s: Finite = 0.0


class StationSpots(Message, frozen=True, kw_only=True):
    """A station's spots as its controller sees them: who sits on each
    (``landed``) and who may land on each (``granted``), by spot index."""

    station_id: Id
    stamp_s: Finite = 0.0
    landed: list[Id | None] = []
    granted: list[Id | None] = []
