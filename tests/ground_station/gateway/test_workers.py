"""The gateway's view of worker poses: trusted by key, never from the future."""

from __future__ import annotations

from ground_station.gateway.workers import WorkerPoses
from linecrew_runtime.scenarios import load
from proto.geo import GeoPoint, Point
from proto.keys import KeySpace
from proto.telemetry import HumanPose

SITE = load("paper").site
KEYS = KeySpace(SITE.id)
NOW = 1_000_000.0


def pose(worker_id: str, stamp_s: float, x_m: float) -> HumanPose:
    return HumanPose(
        worker_id=worker_id, stamp_s=stamp_s, position=Point(x_m=x_m, y_m=0), geo=GeoPoint()
    )


def view(poses: WorkerPoses, worker_id: str):
    return next(w for w in poses.reply().workers if w.worker_id == worker_id)


def test_a_pose_is_kept_only_from_its_own_worker_key_and_not_from_the_future():
    worker, other = SITE.workers[0].id, SITE.workers[1].id
    poses = WorkerPoses(SITE, clock=lambda: NOW)
    poses.on_pose(KEYS.human_pose(other), pose(worker, NOW, 50))  # another worker's key
    poses.on_pose(KEYS.human_pose(worker), pose(worker, NOW + 3600, 60))  # an hour ahead
    assert not view(poses, worker).tracked and poses.refused == 2
    poses.on_pose(KEYS.human_pose(worker), pose(worker, NOW - 1, 10))
    seen = view(poses, worker)
    assert seen.tracked and seen.position.x_m == 10 and seen.age_s == 1
