"""Where this UAV may land at a charging station: the spot the station's
controller granted it (:mod:`proto.spots`), claimed from the spots its
feed shows free; until the grant comes, a hold point beside the station's
row of spots (``HOLD_ASIDE_M``), at a height of its own (``approach_alt_m``
plus ``HOLD_STEP_M`` per place in the fleet), so that UAVs waiting for one
station never meet, nor meet one landing or taking off; flights to a
station cross at that height too.

A station whose controller is unheard for ``STALE_S`` real seconds (the UAV
is cut off, or the station has no controller) is landed on unannounced, so
that a partition never keeps a UAV in the air: at home on the UAV's own
home spot, which no other UAV is ever granted (cut-off UAVs therefore go
home when they can reach it, see :func:`onboard_agent.targets.landing_station`);
elsewhere on a shared spot the last feed showed free, the UAV's place in
the fleet choosing among several so that two cut-off UAVs seldom pick
the same one. Never between spots."""

from __future__ import annotations

import math
import time
from collections.abc import Callable

from proto.geo import Point
from proto.scenario import Scenario
from proto.site import ChargingStation, Site
from proto.spots import SpotClaim, StationSpots, spot_owners, spot_positions

HOLD_STEP_M = 2.0
"""Height between the hold points of two UAVs of the fleet."""
HOLD_ASIDE_M = 3.0
"""Hold points lie this far beside the station's row of spots (along +y;
the spots run along +x): a UAV coming down to its spot or climbing out of
one passes 3 m from the UAVs holding there, not through their column
(chaos seed 11: one descending to its spot 0.96 m from one holding)."""
CLAIM_EVERY_S = 1.0
"""A claim not granted yet is repeated this often (mission seconds)."""
UNUSED_S = 5.0
"""A grant the UAV has not flown to for this long is given back, and a
wanted spot not asked for again for this long is no longer claimed."""
STALE_S = 3.0
"""A station feed unheard this long (real seconds, as the ground-station
link's timeout: a speed-up must not shorten it) no longer gates landing."""


def _hold_z(station: ChargingStation, approach_alt_m: float, place: int) -> float:
    """The height the UAV at ``place`` in the fleet holds at over ``station``."""
    return station.position.z_m + approach_alt_m + HOLD_STEP_M * (1 + place)


class Spots:
    """The stations' spot feeds and this UAV's claims."""

    def __init__(
        self,
        uav_id: str,
        scenario: Scenario,
        link_clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.uav_id = uav_id
        self.fleet = scenario.fleet
        self.link_clock = link_clock
        self._places = {u.id: i for i, u in enumerate(scenario.fleet.uavs)}
        self.place = self._place(uav_id)
        self._owners = {s.id: spot_owners(s, self.fleet) for s in scenario.site.stations}
        self.home_station = next(
            (u.home_station for u in scenario.fleet.uavs if u.id == uav_id), None
        )
        self._feeds: dict[str, StationSpots] = {}
        self._wanted: tuple[str, int] | None = None
        self._claimed: tuple[str | None, int] | None = None
        self._claimed_s = -math.inf
        self._used_s: dict[str, float] = {}
        self._heard_s: dict[str, float] = {}

    def raised_spots(self, site: Site) -> list[Point]:
        """Every spot of a station standing above the site's ground (a roof):
        obstacles a route must clear as it clears people (the deck is solid)."""
        ground = site.safety.ground_z_m
        return [
            p
            for s in site.stations
            if s.position.z_m > ground
            for p in spot_positions(s, self.fleet)
        ]

    def busy_columns(self, site: Site, approach_alt_m: float) -> list[Point]:
        """Above every spot another UAV is granted or sits on (as the last
        feeds show), at that UAV's hold height: it comes down from there or
        climbs out through it, so a route crosses the column above it as it
        passes a person (chaos seed 15: a UAV flying to its station crossed
        the column another came down through)."""
        out = []
        for station in site.stations:
            feed = self._feeds.get(station.id)
            if feed is None:
                continue
            spots = spot_positions(station, self.fleet)
            for point, granted, landed in zip(spots, feed.granted, feed.landed, strict=False):
                other = next((u for u in (granted, landed) if u not in (None, self.uav_id)), None)
                if other is None:
                    continue
                z = _hold_z(station, approach_alt_m, self._place(other))
                out.append(Point(x_m=point.x_m, y_m=point.y_m, z_m=z))
        return out

    def update(self, feed: StationSpots) -> None:
        """The newest feed of a station (an older stamp is ignored)."""
        known = self._feeds.get(feed.station_id)
        if known is None or feed.stamp_s >= known.stamp_s:
            self._feeds[feed.station_id] = feed
            self._heard_s[feed.station_id] = self.link_clock()

    def _live(self, station_id: str) -> bool:
        heard = self._heard_s.get(station_id)
        return heard is not None and self.link_clock() - heard <= STALE_S

    def cut_off(self) -> bool:
        """Whether the controllers this UAV heard are all unheard for
        ``STALE_S`` (never heard any: a site without them, not a cut)."""
        return bool(self._heard_s) and not any(self._live(s) for s in self._heard_s)

    def granted(self, station_id: str) -> int | None:
        """The spot of ``station_id`` granted to this UAV, if any."""
        feed = self._feeds.get(station_id)
        if feed is None:
            return None
        return next((i for i, g in enumerate(feed.granted) if g == self.uav_id), None)

    def has_room(self, station_id: str) -> bool:
        """Whether this UAV can land at ``station_id`` now or after a claim."""
        if not self._live(station_id):
            return self._unannounced(station_id) is not None
        return self._free(station_id) is not None

    def cleared(self, station_id: str) -> bool:
        """Whether this UAV may land at ``station_id`` now: granted, or its
        controller unheard for ``STALE_S`` and a spot to land on unannounced."""
        if self.granted(station_id) is not None:
            return True
        return not self._live(station_id) and self._unannounced(station_id) is not None

    def landing_point(self, station: ChargingStation, now_s: float) -> Point | None:
        """Where to land at ``station``: the granted spot, or the spot to land
        on unannounced while its controller is unheard; None while a claim
        waits for its grant (or no spot is free)."""
        self._used_s[station.id] = now_s
        spot = self.granted(station.id)
        if spot is None and not self._live(station.id):
            spot = self._unannounced(station.id)
        if spot is not None:
            self._wanted = None
            return spot_positions(station, self.fleet)[spot]
        free = self._free(station.id)
        self._wanted = (station.id, free) if free is not None else None
        return None

    @property
    def layer(self) -> tuple[int, int]:
        """This UAV's place in the fleet and the fleet's size: the cruise
        levels of its own (:func:`onboard_agent.route.own_level`)."""
        return self.place, len(self.fleet.uavs)

    def hold_point(self, station: ChargingStation, approach_alt_m: float) -> Point:
        """Where this UAV waits for a spot at ``station``: beside its row of
        spots (``HOLD_ASIDE_M``), at a height of its own."""
        p = station.position
        return Point(
            x_m=p.x_m, y_m=p.y_m + HOLD_ASIDE_M, z_m=_hold_z(station, approach_alt_m, self.place)
        )

    def claim_due(self, now_s: float) -> SpotClaim | None:
        """The claim to send now, if any: a wanted spot (again every
        ``CLAIM_EVERY_S`` until granted), or giving back a grant unused for
        ``UNUSED_S``."""
        if self._wanted is not None and self._unused(self._wanted[0], now_s):
            self._wanted = None  # e.g. the plan moved on before the grant came
        want: tuple[str | None, int] | None = self._wanted
        if want is None:
            stale = [
                s for s in self._feeds if self.granted(s) is not None and self._unused(s, now_s)
            ]
            want = (None, 0) if stale else None
        if want is None:
            return None
        if want == self._claimed and now_s - self._claimed_s < CLAIM_EVERY_S:
            return None
        self._claimed, self._claimed_s = want, now_s
        return SpotClaim(uav_id=self.uav_id, station_id=want[0], spot=want[1], stamp_s=now_s)

    def _unused(self, station_id: str, now_s: float) -> bool:
        """Whether this UAV has not asked where to land at ``station_id``
        for ``UNUSED_S`` (or ever: a grant it never asked for)."""
        return now_s - self._used_s.get(station_id, -math.inf) > UNUSED_S

    def _open(self, station_id: str) -> list[int]:
        """The spots of ``station_id`` this UAV may claim as its last feed
        shows them (every shared one if none was heard)."""
        owners = self._owners.get(station_id, [])
        feed = self._feeds.get(station_id)
        if feed is None:
            return [i for i, owner in enumerate(owners) if owner is None]
        return [
            i
            for i, (granted, landed) in enumerate(zip(feed.granted, feed.landed, strict=False))
            if granted is None
            and landed in (None, self.uav_id)
            and (i >= len(owners) or owners[i] in (None, self.uav_id))
        ]

    def _free(self, station_id: str) -> int | None:
        """The spot to claim at ``station_id``: the granted one, else this
        UAV's home spot, else the first free shared one (None: full)."""
        mine = self.granted(station_id)
        if mine is not None:
            return mine
        if station_id not in self._feeds:
            return None
        free = self._open(station_id)
        home = self._home(station_id)
        return home if home in free else next(iter(free), None)

    def _unannounced(self, station_id: str) -> int | None:
        """The spot to land on at ``station_id`` without a grant: the home
        spot; else a shared one free in the last feed, chosen by this UAV's
        place in the fleet."""
        home = self._home(station_id)
        if home is not None:
            return home
        free = self._open(station_id)
        return free[self.place % len(free)] if free else None

    def _place(self, uav_id: str) -> int:
        """``uav_id``'s place in the fleet (after the fleet's UAVs if unknown)."""
        return self._places.get(uav_id, len(self._places))

    def _home(self, station_id: str) -> int | None:
        owners = self._owners.get(station_id, [])
        return owners.index(self.uav_id) if self.uav_id in owners else None
