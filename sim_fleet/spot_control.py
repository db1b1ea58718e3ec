"""The charging stations' controllers: which UAV sits on each landing spot
and which one may land there (see :mod:`proto.spots`).

``SpotControl`` is the logic (no clock, no bus): claims are granted first
come when the spot is neither taken nor granted to another UAV, nor
another UAV's home spot (``owners``); a grant
ends when its UAV takes off from the spot, claims another, gives it up, or
has not landed within ``grant_ttl_s`` simulated seconds. ``SpotService``
puts it on the bus: claims in on ``uav/*/spot`` (trusted only from the key
of the UAV they name), every station's spots out on ``station/{id}/spots``
a few times a second and at once when a claim changes them."""

from __future__ import annotations

import asyncio
import dataclasses
import logging
import time
from collections.abc import Iterable

from linecrew_runtime.bus import Bus
from proto.keys import KeySpace, UavTopic
from proto.spots import SpotClaim, StationSpots
from sim_fleet.physics import Vec3, horizontal_distance
from sim_fleet.vehicle import Vehicle
from sim_fleet.world import World

log = logging.getLogger(__name__)

GRANT_TTL_S = 600.0
"""Simulated seconds a granted UAV has to land on its spot."""
CLEAR_M = 4.0
"""A UAV that took off from a spot keeps it taken until it is this far from
it horizontally, however high: one granted it next comes down straight
through the spot's column, onto a UAV still climbing out or hovering above
(chaos seed 15: 6 m straight above, a 3-D distance had freed the spot)."""


@dataclasses.dataclass
class _Grant:
    uav_id: str
    since_s: float
    landed: bool = False  # the UAV has sat on the spot since the grant


class SpotControl:
    """Spots by station: who sits on each, who may land on each."""

    def __init__(
        self,
        spots: dict[str, tuple[Vec3, ...]],
        dock_radius_m: float,
        grant_ttl_s: float = GRANT_TTL_S,
        owners: dict[str, tuple[str | None, ...]] | None = None,
    ) -> None:
        self.spots = spots
        self.owners = owners or {}
        self.dock_radius_m = dock_radius_m
        self.grant_ttl_s = grant_ttl_s
        self.landed: dict[str, list[str | None]] = {s: [None] * len(p) for s, p in spots.items()}
        self.grants: dict[str, list[_Grant | None]] = {s: [None] * len(p) for s, p in spots.items()}

    def claim(self, uav_id: str, station_id: str | None, spot: int, now_s: float) -> bool:
        """Grant ``spot`` of ``station_id`` to ``uav_id`` if it is free (True);
        the UAV's other grants end. ``station_id`` None gives them up."""
        if station_id is None:
            self._release(uav_id)
            return True
        if station_id not in self.spots or not 0 <= spot < len(self.spots[station_id]):
            return False
        owners = self.owners.get(station_id, ())
        if spot < len(owners) and owners[spot] not in (None, uav_id):
            return False  # another UAV's home spot
        grant = self.grants[station_id][spot]
        if grant is not None and grant.uav_id == uav_id:
            return True
        sitter = self.landed[station_id][spot]
        if grant is not None or sitter not in (None, uav_id):
            return False
        self._release(uav_id)
        self.grants[station_id][spot] = _Grant(uav_id, now_s, landed=sitter == uav_id)
        return True

    def observe(self, vehicles: Iterable[Vehicle], now_s: float) -> None:
        """Who sits where now (or still climbs out: ``CLEAR_M``); grants
        whose UAV took off or never came end."""
        crafts = {v.id: v for v in vehicles}
        on_ground = [v for v in crafts.values() if not v.airborne]
        for station_id, points in self.spots.items():
            for i, point in enumerate(points):
                sitter = next(
                    (
                        v.id
                        for v in on_ground
                        if horizontal_distance(v.position, point) <= self.dock_radius_m
                    ),
                    None,
                )
                last = crafts.get(self.landed[station_id][i] or "")
                climbing = (
                    sitter is None
                    and last is not None
                    and last.airborne
                    and horizontal_distance(last.position, point) < CLEAR_M
                )
                self.landed[station_id][i] = last.id if climbing and last else sitter
                grant = self.grants[station_id][i]
                if grant is None:
                    continue
                if sitter == grant.uav_id:
                    grant.landed = True
                elif grant.landed or now_s - grant.since_s > self.grant_ttl_s:
                    self.grants[station_id][i] = None

    def state(self, station_id: str, stamp_s: float = 0.0) -> StationSpots:
        """The station's spots as a message."""
        return StationSpots(
            station_id=station_id,
            stamp_s=stamp_s,
            landed=list(self.landed[station_id]),
            granted=[g.uav_id if g else None for g in self.grants[station_id]],
        )

    def _release(self, uav_id: str) -> None:
        for grants in self.grants.values():
            for i, grant in enumerate(grants):
                if grant is not None and grant.uav_id == uav_id:
                    grants[i] = None


class SpotService:
    """:class:`SpotControl` on the bus, watching the simulated world."""

    def __init__(self, control: SpotControl, world: World, bus: Bus, keys: KeySpace) -> None:
        self.control = control
        self.world = world
        self.bus = bus
        self.keys = keys

    def on_claim(self, key: str, claim: SpotClaim) -> None:
        """A claim, trusted only on the key of the UAV it names; answered at once."""
        if not self.keys.owns(key, "uav", claim.uav_id):
            log.warning("dropped a spot claim for %s that came on %s", claim.uav_id, key)
            return
        self.control.observe(self.world.vehicles.values(), self.world.time_s)
        self.control.claim(claim.uav_id, claim.station_id, claim.spot, self.world.time_s)
        self.publish()

    def publish(self) -> None:
        """Every station's spots."""
        for station_id in self.control.spots:
            state = self.control.state(station_id, time.time())
            self.bus.publish(self.keys.station_spots(station_id), state)

    async def run(self, rate_hz: float = 4.0) -> None:
        """Observe and publish at ``rate_hz`` (wall clock) until cancelled."""
        async with self.bus.subscribe_async(self.keys.all_uavs(UavTopic.SPOT), SpotClaim) as claims:
            reader = asyncio.ensure_future(self._claims(claims))
            try:
                while True:
                    self.control.observe(self.world.vehicles.values(), self.world.time_s)
                    self.publish()
                    await asyncio.sleep(1.0 / rate_hz)
            finally:
                reader.cancel()

    async def _claims(self, claims: object) -> None:
        async for key, claim in claims:  # type: ignore[attr-defined]
            try:
                self.on_claim(key, claim)
            except Exception:
                log.exception("spot claim failed: %s", claim)
