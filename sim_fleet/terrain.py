"""The ground under the site: flat terrain at the origin's height (z = 0)
and the stations' decks, which may stand higher (pads on a roof).

A station's deck is at the height of its landing spots and covers every
point within ``radius_m`` (the dock radius) of the chain through its
spots, so a vehicle on or over any spot, or between two, is on the deck;
anywhere else the ground is the terrain.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

from sim_fleet.physics import Vec3

TERRAIN_Z_M = 0.0


def flat(_x: float, _y: float) -> float:
    """The ground of a site without raised decks."""
    return TERRAIN_Z_M


def _segment_distance(x: float, y: float, a: Vec3, b: Vec3) -> float:
    """Horizontal distance from (x, y) to the segment a-b."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    length2 = dx * dx + dy * dy
    t = 0.0 if length2 == 0 else ((x - a[0]) * dx + (y - a[1]) * dy) / length2
    t = min(1.0, max(0.0, t))
    return math.hypot(x - (a[0] + t * dx), y - (a[1] + t * dy))


@dataclass(frozen=True, slots=True)
class Deck:
    """One station's landing deck."""

    spots: tuple[Vec3, ...]
    radius_m: float

    @property
    def z_m(self) -> float:
        return max(p[2] for p in self.spots)

    def covers(self, x: float, y: float) -> bool:
        ends = self.spots[1:] or self.spots  # one spot: a disc
        pairs = zip(self.spots, ends, strict=False)
        return any(_segment_distance(x, y, a, b) <= self.radius_m for a, b in pairs)


class Ground:
    """Where the ground is under any point of the site."""

    def __init__(self, spots: Iterable[tuple[Vec3, ...]], radius_m: float) -> None:
        """``spots``: each station's landing spots."""
        self.decks = tuple(Deck(points, radius_m) for points in spots)

    def z_at(self, x: float, y: float) -> float:
        """The height of the ground (a deck's top, else the terrain) at (x, y)."""
        return max((d.z_m for d in self.decks if d.covers(x, y)), default=TERRAIN_Z_M)
