"""``GET /v1/workers``: where each worker of the site is now.

The gateway follows the human tracker's poses (``human/{id}/pose``) itself,
so the console can draw people where they are, not where the site file
put them. A pose counts only for the worker its key names, and only for a
worker of the site; a pose older than the newest one kept is ignored.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

import msgspec

from proto.geo import Point
from proto.keys import KeySpace
from proto.site import Site
from proto.telemetry import POSE_FUTURE_S, HumanPose


class WorkerView(msgspec.Struct, frozen=True, kw_only=True):
    """One worker: ``tracked`` False means no pose has arrived yet and
    ``position`` is the site's; ``age_s`` is the pose's age (wall seconds)."""

    worker_id: str
    position: Point
    tracked: bool
    age_s: float | None = None


class WorkersReply(msgspec.Struct, frozen=True, kw_only=True):
    """Every worker of the site."""

    workers: list[WorkerView]


class WorkerPoses:
    """The newest pose of each worker of ``site`` (fed on a Zenoh thread)."""

    def __init__(self, site: Site, clock: Callable[[], float] = time.time) -> None:
        self.site = site
        self.keys = KeySpace(site.id)
        self.clock = clock
        self._known = {w.id for w in site.workers}
        self._poses: dict[str, HumanPose] = {}
        self._lock = threading.Lock()
        self.refused = 0  # poses dropped: key and payload disagree, or no such worker

    def on_pose(self, key: str, pose: HumanPose) -> None:
        """Keep ``pose`` if its key names its worker, a worker of the site, and
        it is not stamped beyond :data:`POSE_FUTURE_S` ahead."""
        if pose.worker_id not in self._known or not self.keys.owns(key, "human", pose.worker_id):
            self.refused += 1
            return
        if pose.stamp_s > self.clock() + POSE_FUTURE_S:
            self.refused += 1
            return
        with self._lock:
            known = self._poses.get(pose.worker_id)
            if known is None or pose.stamp_s >= known.stamp_s:
                self._poses[pose.worker_id] = pose

    def reply(self) -> WorkersReply:
        now = self.clock()
        with self._lock:
            poses = dict(self._poses)
        views = []
        for worker in self.site.workers:
            pose = poses.get(worker.id)
            where = worker.position if pose is None else pose.position
            age = None if pose is None else max(0.0, now - pose.stamp_s)
            views.append(
                WorkerView(worker_id=worker.id, position=where, tracked=pose is not None, age_s=age)
            )
        return WorkersReply(workers=views)
