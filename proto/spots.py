"""Landing spots at charging stations, and which UAV may land on which.

A charging station is a row of landing spots along +x, centred on its
position and ``spot_spacing_m`` apart: one per pad, and one more for each
UAV beyond that whose home it is (every UAV has a spot at home). At most
``pads`` of the docked UAVs charge at once. No spot takes two UAVs: the
station's controller (the simulator plays it) grants each spot to one UAV
at a time. A UAV claims a free spot with a :class:`SpotClaim` on
``uav/{id}/spot`` and lands only on a spot that :class:`StationSpots` (on
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


def spot_count(station: ChargingStation, fleet: Fleet) -> int:
    """How many spots ``station`` has: its pads, at least one, and one for
    every UAV whose home it is."""
    homes = sum(1 for u in fleet.uavs if u.home_station == station.id)
    return max(station.pads, 1, homes)


def spot_positions(station: ChargingStation, fleet: Fleet) -> list[Point]:
    """Where the spots of ``station`` are, spot 0 first."""
    n = spot_count(station, fleet)
    p = station.position
    return [
        Point(x_m=p.x_m + (i - (n - 1) / 2) * SPOT_SPACING_M, y_m=p.y_m, z_m=p.z_m)
        for i in range(n)
    ]


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
