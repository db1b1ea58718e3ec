"""The ground station process: the mission manager wired to the bus.

One asyncio loop does all the work; Zenoh callbacks only hand samples over.
Planning runs in one worker (:mod:`ground_station.plan_worker`): requests
reply once their change is committed, and the worker's thread plans.
Inputs: agents' telemetry, status, outcomes and liveliness tokens; RPC
queries on ``gs/rpc/{op}``; plan resync queries on ``uav/*/plan``. Outputs:
plans on ``uav/{id}/plan``, events on ``gs/events``, the ``alive/gs/{id}``
token. On start it rebuilds from the store; agents reappear, a replan follows.
"""

from __future__ import annotations

import asyncio
import logging
import time
import uuid
from collections.abc import Callable
from typing import Any

import msgspec

from ground_station.config import GsConfig
from ground_station.event_log import EventLog
from ground_station.fleet_monitor import FleetMonitor
from ground_station.missions import MissionManager
from ground_station.replan_jobs import ImproveSettings
from ground_station.replanner import Replanner
from ground_station.store import Store
from linecrew_runtime.bus import Bus
from linecrew_runtime.process import Shutdown
from proto.errors import Forbidden
from proto.keys import KeySpace, Role, UavTopic
from proto.rpc import (
    ActionReply,
    CancelAction,
    ControlUav,
    GetAction,
    GetFleet,
    GetHistory,
    GetMetrics,
    GetPlans,
    ListActions,
    MetricsReply,
    ModifyAction,
    PlansReply,
    Reply,
    SubmitAction,
)
from proto.scenario import Scenario
from proto.telemetry import AgentStatus, TaskOutcome, Telemetry

FUTURE_TOLERANCE_S = 60.0
"""How far ahead of the mission clock a UAV's sample may be stamped (clock skew
between machines); later stamps are forged or broken: dropped, counted."""

log = logging.getLogger("linecrew.ground_station")


class GroundStation:
    """Builds the components and runs them until shutdown."""

    def __init__(
        self,
        config: GsConfig,
        scenario: Scenario,
        bus: Bus,
        clock: Callable[[], float] = time.time,
        speedup: float = 1.0,
        link_clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.config = config
        self.link_clock = link_clock  # real seconds: silences, losses, traffic ages
        self.traffic_period_s = config.traffic_period(speedup)
        self.bus = bus
        self.clock = clock
        self.keys = KeySpace(scenario.site.id)
        self.identity_mismatches = 0  # samples dropped: their ids disagree with their key
        self.future_stamps = 0  # samples dropped: stamped too far in the future
        self.generation = f"gs-{uuid.uuid4().hex[:12]}"  # this run, in every traffic report
        self.store = Store(config.db_path)
        self.monitor = FleetMonitor(
            [u.id for u in scenario.fleet.uavs], config.link_timeout_s, mission_clock=clock
        )
        self.events = EventLog(self.store, lambda e: bus.publish(self.keys.events(), e), clock)
        self.replanner = Replanner(
            scenario=scenario,
            store=self.store,
            monitor=self.monitor,
            events=self.events,
            send=lambda plan: bus.publish(self.keys.plan(plan.uav_id), plan),
            improve=ImproveSettings(
                enabled=bool(config.improve),
                rounds=config.improve_rounds,
                margin=config.improve_margin,
                freeze_s=config.freeze_horizon_s,
                attempts=config.improve_attempts,
            ),
            session_window_s=config.session_window_s,
        )
        self.manager = MissionManager(
            scenario=scenario,
            store=self.store,
            monitor=self.monitor,
            events=self.events,
            replanner=self.replanner,
            clock=clock,
            battery_margin_fraction=config.battery_margin_fraction,
            improve=bool(config.improve),
            improve_delay_s=config.improve_delay_s,
        )

    async def run(self, shutdown: Shutdown) -> None:
        """Serve until ``shutdown``; then undeclare everything and close the store."""
        keys, bus = self.keys, self.bus
        try:
            for request_type, answer in self.answers().items():
                bus.serve(keys.rpc(request_type.op), request_type, answer)
            bus.serve(keys.all_uavs(UavTopic.PLAN), GetPlans, self._plan_query, with_key=True)
            telemetry = bus.subscribe_async(keys.all_uavs(UavTopic.TELEMETRY), Telemetry)
            status = bus.subscribe_async(keys.all_uavs(UavTopic.STATUS), AgentStatus)
            outcomes = bus.subscribe_async(keys.all_uavs(UavTopic.OUTCOME), TaskOutcome)
            tokens = bus.watch_liveliness_async(keys.all_alive(Role.AGENT))
            bus.declare_token(keys.alive(Role.GROUND_STATION, self.config.gs_id))
            log.info(
                "ground station up",
                extra={
                    "site": keys.site,
                    "db": self.config.db_path,
                    "actions": len(self.store.actions()),
                },
            )
            async with asyncio.TaskGroup() as group:
                tasks = [
                    group.create_task(self._consume(telemetry, self._on_telemetry)),
                    group.create_task(self._consume(status, self._on_status)),
                    group.create_task(self._consume(outcomes, self._on_outcome)),
                    group.create_task(self._consume(tokens, self._on_token)),
                    group.create_task(self._watchdog()),
                    group.create_task(self._traffic()),
                    group.create_task(self.manager.worker.run()),
                ]
                await shutdown.wait_async()
                for task in tasks:
                    task.cancel()
        finally:
            self.store.close()

    async def _consume(self, source: Any, handle: Callable[[str, Any], None]) -> None:
        async for key, item in source:
            try:
                handle(key, item)
            except Exception:
                log.exception("failed to handle a message on %s", key)

    def _bound(self, key: str, uav_id: str, stamp_s: float) -> bool:
        """Whether a sample about ``uav_id`` came on that UAV's own key (under
        the secured profile, only its certificate may publish there) and is
        not stamped beyond :data:`FUTURE_TOLERANCE_S` of mission time ahead;
        one that fails either is dropped and counted."""
        if not self.keys.owns(key, "uav", uav_id):
            self.identity_mismatches += 1
            log.warning("dropped a sample about %s that came on %s", uav_id, key)
            return False
        if stamp_s > self.clock() + FUTURE_TOLERANCE_S:
            self.future_stamps += 1
            log.warning("dropped a sample on %s stamped %.0f s ahead", key, stamp_s - self.clock())
            return False
        return self.monitor.known(uav_id)

    def _on_telemetry(self, key: str, telemetry: Telemetry) -> None:
        if self._bound(key, telemetry.uav_id, telemetry.stamp_s):
            self.monitor.on_telemetry(telemetry, self.link_clock())
            self.manager.reports.on_telemetry(telemetry)

    def _on_status(self, key: str, status: AgentStatus) -> None:
        if self._bound(key, status.uav_id, status.stamp_s):
            self.monitor.on_status(status, self.link_clock())
            self.manager.reports.on_status(status)

    def _on_outcome(self, key: str, outcome: TaskOutcome) -> None:
        if self._bound(key, outcome.uav_id, outcome.stamp_s):
            self.manager.reports.on_outcome(outcome)

    def _on_token(self, key: str, alive: bool) -> None:
        parsed = self.keys.parse(key)
        if parsed.ident is not None:
            self.monitor.on_token(parsed.ident, alive, self.link_clock())

    async def _watchdog(self) -> None:
        while True:
            try:
                self.manager.retry_unsaved()
                self.manager.on_fleet_changes(self.monitor.check(self.link_clock()))
                self.manager.retry_unplaced()
            except Exception:
                log.exception("watchdog step failed")
            await asyncio.sleep(self.config.watchdog_period_s)

    async def _traffic(self) -> None:
        """Tell the agents where every UAV is, ``traffic_period_s`` apart."""
        while True:
            try:
                report = self.monitor.traffic(self.link_clock())
                epoch = self.store.counter("epoch")
                announced = msgspec.structs.replace(report, generation=self.generation, epoch=epoch)
                self.bus.publish(self.keys.traffic(), announced)
            except Exception:
                log.exception("traffic report not sent")
            await asyncio.sleep(self.traffic_period_s)

    def answers(self) -> dict[type[Any], Callable[[Any], Reply]]:
        """The one table from each operator request to its answer. Each is
        served on ``gs/rpc/{op}`` and decoded as its own type only, so a
        request sent to another operation's key is a ``decode_error``."""
        m = self.manager
        return {
            SubmitAction: lambda r: ActionReply(record=m.submit(r)),
            ModifyAction: lambda r: ActionReply(record=m.modify(r)),
            CancelAction: lambda r: ActionReply(record=m.cancel(r)),
            GetAction: lambda r: ActionReply(record=m.book.record(r.action_id)),
            ListActions: m.list_actions,
            GetFleet: lambda _: m.fleet(),
            ControlUav: m.control,
            GetPlans: lambda r: m.plans(r.uav_id),
            GetHistory: m.history,
            GetMetrics: lambda _: MetricsReply(values=self.metrics()),
        }

    def _plan_query(self, key: str, request: GetPlans) -> PlansReply:
        """A UAV's plan, to the UAV whose key the query was sent to only."""
        parsed = self.keys.parse(key)  # a wildcard query is no UAV's: refused
        if parsed.kind != "uav" or not parsed.ident or request.uav_id not in (None, parsed.ident):
            raise Forbidden(
                f"a query on {key} reads only the plan of {parsed.ident}", field="uav_id"
            )
        return self.manager.plans(parsed.ident)  # as an operator sees it

    def metrics(self) -> dict[str, float]:
        """Counters and timings in one place."""
        stats, counters = self.replanner.stats, self.manager.reports.counters
        worker = self.manager.worker.stats
        values: dict[str, float] = {
            "replans": stats.count,
            "replan_seconds_total": stats.total_s,
            "replan_seconds_last": stats.last_s,
            "plans_sent": stats.plans_sent,
            "replans_unchanged": stats.unchanged,
            "replans_incremental": stats.incremental,
            "replans_rebuilt": stats.rebuilds,
            "replans_dropped": stats.dropped,
            "replan_triggers": worker.triggers,
            "replan_triggers_coalesced": worker.coalesced,
            "improvements_tried": stats.improvements_tried,
            "improvements_adopted": stats.improvements_adopted,
            "improvements_rejected": stats.improvements_rejected,
            "improvements_interrupted": stats.improvements_interrupted,
            "planner_settled": float(self.manager.worker.settled),
            "outcomes": counters.outcomes,
            "stale_outcomes": counters.stale_outcomes,
            "battery_replans": counters.battery_replans,
            "epoch": self.store.counter("epoch"),
            "bus_malformed": sum(self.bus.stats.malformed.values()),
            "bus_identity_mismatch": self.identity_mismatches,
            "bus_future_stamps": self.future_stamps,
            "store_failing": float(self.store.failing is not None),
            "events_unstored": self.events.unstored,
        }
        plan_quality = self.manager.plan_quality()
        quality = {
            "plan_objective_s": plan_quality["objective_s"],
            "plan_improved_ago_s": plan_quality["improved_ago_s"],
            "plan_gap_to_best": plan_quality["gap_to_best"],
        }
        for name, value in quality.items():
            if value is not None:
                values[name] = float(value)
        for state, count in self.store.action_counts().items():
            values[f"actions_{state}"] = count
        return values
