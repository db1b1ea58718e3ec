"""The simulated human tracker: moves scripted workers in the world and
publishes every worker's pose on ``human/{id}/pose`` a few times a second."""

from __future__ import annotations

import asyncio
import time
from collections.abc import Callable

from linecrew_runtime.bus import Bus
from proto.geo import Point, SiteFrame
from proto.keys import KeySpace
from proto.site import Site
from proto.telemetry import HumanPose
from sim_fleet.workers import worker_position
from sim_fleet.world import World


class HumanTracker:
    """Publishes worker poses from the simulated world, stamped on the
    mission clock (``clock``) as telemetry is."""

    def __init__(
        self, site: Site, world: World, bus: Bus, clock: Callable[[], float] = time.time
    ) -> None:
        self.site = site
        self.clock = clock
        self.world = world
        self.bus = bus
        self.keys = KeySpace(site.id)
        self.frame = SiteFrame(site.origin)

    def publish_once(self) -> None:
        """Move scripted workers along their paths, and publish every pose
        (a worker without a path stays where the world has it)."""
        for worker in self.site.workers:
            if worker.path:
                position = worker_position(worker, self.world.time_s)
                self.world.move_worker(worker.id, (position.x_m, position.y_m, position.z_m))
            else:
                x, y, z = self.world.workers[worker.id]
                position = Point(x_m=x, y_m=y, z_m=z)
            pose = HumanPose(
                worker_id=worker.id,
                stamp_s=self.clock(),
                position=position,
                geo=self.frame.to_geodetic(position),
            )
            self.bus.publish(self.keys.human_pose(worker.id), pose)

    async def run(self, rate_hz: float = 4.0) -> None:
        """Publish at ``rate_hz`` (wall clock) until cancelled."""
        while True:
            self.publish_once()
            await asyncio.sleep(1.0 / rate_hz)
