"""A stand-in ground station behind the real gateway app: ``n`` UAVs flying
circles whose telemetry changes ``rate_hz`` times a second, a plan per UAV
whose epoch moves every few seconds (with a ``plan_changed`` event on the
stream). For the console's serving tests and its frame-time bench, where a
real 50-UAV fleet would measure the simulator rather than the page, and for
the gateway's in-process tests (:attr:`FakeClient.refusal` makes the next
request fail as the ground station would refuse it)."""

from __future__ import annotations

import asyncio
import contextlib
import itertools
import math
import threading
import time
from collections.abc import Iterator
from typing import Any

import msgspec
import uvicorn

from ground_station.gateway import GatewaySettings, Vocabulary, create_app
from ground_station.gateway.workers import WorkerPoses
from linecrew_runtime.bus.router_process import free_port
from proto import KeySpace
from proto.errors import LinecrewError, NotFound
from proto.events import EventKind, GsEvent
from proto.geo import GeoPoint, Point
from proto.mission import ActionRecord, ActionState
from proto.plan import GoHomeTask, InspectTask, MonitorTask, Plan, RechargeTask, Waypoint
from proto.rpc import (
    ActionList,
    ActionReply,
    FleetReply,
    GetAction,
    GetFleet,
    GetHistory,
    GetMetrics,
    GetPlans,
    HistoryReply,
    ListActions,
    MetricsReply,
    PlansReply,
    SubmitAction,
    UavOpState,
    UavState,
)
from proto.sim import FaultApplied, SimFault
from proto.site import ChargingStation, Line, Site, Tool, ToolStation, Tower, Worker
from proto.telemetry import AgentState, AgentStatus, FlightState, HumanPose, Telemetry

TOKEN = "fake-fleet-token"


def big_site(towers: int = 12, stations: int = 6) -> Site:
    """A line of towers 40 m apart with stations, tool stations and workers."""
    return Site(
        id="bench",
        origin=GeoPoint(lat_deg=37.4, lon_deg=-6.0, alt_m=10.0),
        towers=[
            Tower(id=f"T{i}", position=Point(x_m=40.0 * i, y_m=10.0 * math.sin(i), z_m=20.0))
            for i in range(towers)
        ],
        lines=[Line(id="L1", tower_ids=[f"T{i}" for i in range(towers)])],
        stations=[
            ChargingStation(id=f"C{i}", position=Point(x_m=80.0 * i + 20, y_m=-30.0), pads=4)
            for i in range(stations)
        ],
        tool_stations=[
            ToolStation(
                id=f"tp-{i}",
                position=Point(x_m=100.0 * i + 10, y_m=30.0, z_m=3.0),
                tools=[Tool(name=f"tool{i}", count=2)],
            )
            for i in range(3)
        ],
        workers=[
            Worker(id=f"W{i}", position=Point(x_m=90.0 * i + 30, y_m=5.0, z_m=3.0))
            for i in range(5)
        ],
    )


class FakeFleet:
    """The fleet's state as a function of time."""

    def __init__(self, site: Site, uavs: int = 50, rate_hz: float = 5.0) -> None:
        self.site = site
        self.ids = [f"uav-{i + 1}" for i in range(uavs)]
        self.rate_hz = rate_hz
        self.started = time.time()
        self.epoch_every_s = 3.0

    def now(self) -> float:
        """Time, quantised to the telemetry rate."""
        return math.floor(time.time() * self.rate_hz) / self.rate_hz

    def _pose(self, i: int, now: float) -> tuple[Point, float]:
        span = max(t.position.x_m for t in self.site.towers) or 100.0
        cx, cy = (i * 37.0) % span, ((i * 13) % 7 - 3) * 12.0
        r, w = 8.0 + i % 5 * 4.0, 0.2 + (i % 7) * 0.03
        a = w * (now - self.started) + i
        p = Point(x_m=cx + r * math.cos(a), y_m=cy + r * math.sin(a), z_m=10.0 + i % 10)
        heading = (math.degrees(math.atan2(math.cos(a), -math.sin(a))) + 360.0) % 360.0
        return p, heading

    def fleet(self) -> list[UavState]:
        now = self.now()
        out = []
        for i, uav_id in enumerate(self.ids):
            p, heading = self._pose(i, now)
            battery = 0.3 + 0.7 * (1 - ((now - self.started) / 600 + i / 50) % 1)
            telemetry = Telemetry(
                uav_id=uav_id,
                stamp_s=now,
                position=p,
                geo=self.site.origin,
                heading_deg=heading,
                battery_wh=20.0 * battery,
                battery_fraction=battery,
                flight_state=FlightState.FLYING,
                armed=True,
                mode="GUIDED",
            )
            status = AgentStatus(
                uav_id=uav_id,
                stamp_s=now,
                state=AgentState.BUSY,
                epoch=self.epoch(),
                task_id=f"{uav_id}.t{self.epoch()}.0",
                progress=(now % 30) / 30,
                holding_for=self.ids[0] if i == 1 else None,  # uav-2 waits for uav-1's point
            )
            out.append(
                UavState(uav_id=uav_id, state=UavOpState.BUSY, telemetry=telemetry, status=status)
            )
        return out

    def epoch(self) -> int:
        return int((time.time() - self.started) / self.epoch_every_s) + 1

    def plans(self) -> list[Plan]:
        epoch, now = self.epoch(), self.now()
        plans = []
        for i, uav_id in enumerate(self.ids):
            p, _ = self._pose(i, now)
            start = now - 5 - i % 4
            worker = self.site.workers[i % len(self.site.workers)]
            station = self.site.stations[i % len(self.site.stations)]
            tasks: list[Any] = [
                InspectTask(
                    task_id=f"{uav_id}.t{epoch}.0",
                    action_id=f"act-{i:05d}",
                    start_s=start,
                    end_s=start + 40 + i % 9 * 5,
                    waypoints=[
                        Waypoint(index=k, position=Point(x_m=p.x_m + 10 * k, y_m=p.y_m, z_m=8.0))
                        for k in range(3)
                    ],
                ),
                MonitorTask(
                    task_id=f"{uav_id}.t{epoch}.1",
                    action_id=f"act-m{i % 5}",
                    start_s=start + 60,
                    end_s=start + 160,
                    worker_id=worker.id,
                    slot=0,
                    slots=1,
                    standoff_m=5.0,
                    duration_s=100.0,
                ),
                RechargeTask(
                    task_id=f"{uav_id}.t{epoch}.2",
                    start_s=start + 170,
                    end_s=start + 230,
                    station_id=station.id,
                    position=station.position,
                ),
                GoHomeTask(
                    task_id=f"{uav_id}.t{epoch}.3",
                    start_s=start + 230,
                    end_s=start + 250,
                    station_id=station.id,
                    position=station.position,
                ),
            ]
            plans.append(Plan(uav_id=uav_id, epoch=epoch, issued_s=now, tasks=tasks))
        return plans


class _Events:
    """What ``bus.subscribe_async`` yields: a ``plan_changed`` per new epoch."""

    def __init__(self, fleet: FakeFleet, seq: Iterator[int]) -> None:
        self.fleet = fleet
        self.seq = seq
        self.seen = fleet.epoch()

    async def __aenter__(self) -> _Events:
        return self

    async def __aexit__(self, *_exc: object) -> None:
        return None

    async def get(self) -> tuple[str, GsEvent]:
        while self.fleet.epoch() == self.seen:
            await asyncio.sleep(0.05)
        self.seen = self.fleet.epoch()
        event = GsEvent(
            seq=next(self.seq),
            stamp_s=time.time(),
            kind=EventKind.PLAN_CHANGED,
            epoch=self.seen,
            detail=f"{len(self.fleet.ids)} plans",
        )
        return "events", event


class _Bus:
    def __init__(self, fleet: FakeFleet) -> None:
        self.fleet = fleet
        self.seq = itertools.count(1)

    def subscribe_async(self, _key: str, _type: Any) -> _Events:
        return _Events(self.fleet, self.seq)


class FakeClient:
    """Answers the gateway's ground-station requests from a :class:`FakeFleet`."""

    def __init__(self, fleet: FakeFleet) -> None:
        self.fleet = fleet
        self.keys = KeySpace(fleet.site.id)
        self.bus = _Bus(fleet)
        self.actions: dict[str, ActionRecord] = {}
        self.faults: list[SimFault] = []
        self.refusal: LinecrewError | None = None  # raised by the next request, once
        self.requests: list[Any] = []

    async def call(self, request: Any, _reply_type: Any = None) -> Any:
        self.requests.append(request)
        refusal, self.refusal = self.refusal, None
        if refusal is not None:
            raise refusal
        match request:
            case GetFleet():
                return FleetReply(uavs=self.fleet.fleet())
            case GetPlans():
                return PlansReply(plans=self.fleet.plans())
            case ListActions():
                return ActionList(records=list(self.actions.values()))
            case GetAction(action_id=action_id) if action_id not in self.actions:
                raise NotFound(f"no action {action_id!r}", field="action_id")
            case GetAction():
                return ActionReply(record=self.actions[request.action_id])
            case SubmitAction():
                action_id = request.action_id or f"act-{len(self.actions) + 1:05d}"
                record = ActionRecord(
                    action_id=action_id,
                    action=request.action,
                    state=ActionState.ACCEPTED,
                    created_s=time.time(),
                    request_id=request.request_id,
                )
                self.actions[action_id] = record
                return ActionReply(record=record)
            case GetHistory():
                return HistoryReply(events=[])
            case GetMetrics():
                return MetricsReply(values={})
        raise NotImplementedError(type(request).__name__)

    async def fault(self, fault: SimFault) -> FaultApplied:
        self.faults.append(fault)
        target = getattr(fault, "uav_id", None) or getattr(fault, "worker_id", "?")
        return FaultApplied(target=target, detail=f"fake {type(fault).__name__}", sim_time_s=1.0)

    def ground_station_up(self) -> bool:
        return True


def fake_app(uavs: int = 50, rate_hz: float = 5.0, site: Site | None = None):
    """The real gateway app over a fake fleet; (app, client)."""
    site = site or big_site()
    client = FakeClient(FakeFleet(site, uavs, rate_hz))
    settings = GatewaySettings(token=TOKEN, site=site.id)
    workers = WorkerPoses(site)
    first = site.workers[0]  # tracked 3 m east of where the site puts them; the rest untracked
    moved = msgspec.structs.replace(first.position, x_m=first.position.x_m + 3.0)
    pose = HumanPose(worker_id=first.id, stamp_s=time.time(), position=moved, geo=GeoPoint())
    workers.on_pose(KeySpace(site.id).human_pose(first.id), pose)
    app = create_app(settings, client, site, Vocabulary.load(), workers)  # type: ignore[arg-type]
    return app, client


@contextlib.contextmanager
def serving(app: Any) -> Iterator[str]:
    """Serve ``app`` with uvicorn on a free port in a thread; yields its URL."""
    port = free_port()
    config = uvicorn.Config(
        app,
        host="127.0.0.1",
        port=port,
        log_level="warning",
        access_log=False,
        timeout_graceful_shutdown=1,
    )
    server = uvicorn.Server(config)
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    deadline = time.monotonic() + 10
    while not server.started:
        if time.monotonic() > deadline or not thread.is_alive():
            raise RuntimeError("fake gateway did not start")
        time.sleep(0.02)
    try:
        yield f"http://127.0.0.1:{port}"
    finally:
        server.should_exit = True
        thread.join(5)
