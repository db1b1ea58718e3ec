"""The event each fleet change is told by: its kind and the operator's line."""

from __future__ import annotations

from ground_station.fleet_monitor import Change, FleetMonitor
from linecrew_runtime.clock import time_of_day
from proto.events import EventKind

KINDS = {
    Change.LOST: EventKind.UAV_LOST,
    Change.BACK: EventKind.UAV_BACK,
    Change.CRASHED: EventKind.UAV_CRASHED,
    Change.FAILED: EventKind.UAV_LOST,
    Change.NOT_READY: EventKind.UAV_STATE,
    Change.SILENT: EventKind.UAV_SILENT,
    Change.HEARD: EventKind.UAV_HEARD,
}
TEXT = {
    Change.LOST: "silent past the link timeout; its work goes to others",
    Change.BACK: "heard again; it gets a fresh plan",
    Change.CRASHED: "telemetry says crashed; its work goes to others at once",
    Change.FAILED: "its agent reports failed; its work goes to others at once",
    Change.NOT_READY: "not ready (its autopilot cannot arm yet); its work goes to others "
    "until it is",
    Change.HEARD: "heard again within the link timeout; its tasks go on as planned",
}
TOLD_ONLY = frozenset({Change.SILENT, Change.HEARD})
"""Changes that are only told: the UAV keeps its work, nothing is replanned."""


def fleet_event(monitor: FleetMonitor, uav_id: str, change: Change) -> tuple[EventKind, str]:
    """The kind and detail of the event telling ``change`` of ``uav_id``."""
    detail = TEXT.get(change, "")
    status = monitor.status(uav_id)
    if change == Change.NOT_READY and status is not None and status.reason:
        detail = f"{status.reason}; its work goes to others until it is ready"
    since = monitor.silent_since(uav_id)
    if change == Change.SILENT and since is not None:
        detail = (
            f"silent since {time_of_day(since)} (mission clock); its tasks are unknown until "
            f"it is heard again, or lost after {monitor.link_timeout_s:g} s of silence"
        )
    return KINDS[change], detail
