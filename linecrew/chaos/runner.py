"""The chaos run: a :class:`LocalRun` of the scenario (with ``netns``, a
:class:`~linecrew.chaos.netns_run.NetnsRun`: real cuts), its scripted actions,
then the seeded schedule of injections, with the invariants checked on every
sample (gateway + simulator truth, twice a wall second) and a drain phase in
which every accepted action must end.

Submissions whose outcome is unknown (the ground station was down: 503,
timeout) are retried with the same ``request_id`` until they get an answer,
so "accepted" always means a 2xx the operator saw. Cuts and their heals run
on a :class:`Timeline` thread, on time whatever the REST calls of the loop
wait for; kills and restarts stay on the loop (the main thread).
"""

from __future__ import annotations

import dataclasses
import heapq
import logging
import pathlib
import time
from collections.abc import Callable
from typing import Any

import httpx
import msgspec

from linecrew.chaos.cuts import process_name
from linecrew.chaos.faults import ProcessFaults
from linecrew.chaos.injections import APPLIERS, Context
from linecrew.chaos.invariants import TERMINAL, Checker
from linecrew.chaos.netns_run import NetnsRun
from linecrew.chaos.schedule import CUTS, Injection, make_schedule
from linecrew.chaos.timeline import Timeline
from linecrew.launch.local_run import LocalRun, RunOptions
from linecrew_runtime.process import Shutdown
from proto import GetHistory, GetSimState, HistoryReply, SimState
from proto.errors import LinecrewError
from proto.scenario import Scenario

log = logging.getLogger(__name__)

SAMPLE_EVERY_S = 0.5
RETRY_EVERY_S = 1.0
FINAL_WAIT_S = 10.0  # how long the final action list may take to answer


@dataclasses.dataclass(frozen=True, kw_only=True)
class ChaosOptions:
    """How long and how fast."""

    seed: int
    duration_s: float = 60.0  # wall seconds of injections
    drain_s: float = 150.0  # wall seconds after that for every action to end
    speedup: float = 10.0
    run_dir: pathlib.Path | None = None
    scenario_actions: bool = True  # also submit the scenario's scripted actions
    netns: bool = False  # every process in a network namespace: partitions are real cuts


@dataclasses.dataclass
class Applied:
    """An injection as it happened."""

    injection: Injection
    at_s: float  # wall seconds since start, when applied
    healed_s: float | None = None
    note: str = ""


@dataclasses.dataclass
class ChaosResult:
    """Everything the report needs."""

    options: ChaosOptions
    run_dir: pathlib.Path
    applied: list[Applied]
    checker: Checker
    actions: list[dict[str, Any]] | None
    rejected: dict[str, str]
    event_counts: dict[str, int]
    samples: int
    wall_s: float

    @property
    def ok(self) -> bool:
        """No invariant broken."""
        return not self.checker.violations


class ChaosRunner:
    """One seeded chaos run on a fresh local fleet."""

    def __init__(self, scenario: Scenario, options: ChaosOptions, shutdown: Shutdown) -> None:
        self.scenario = scenario
        self.options = options
        self.shutdown = shutdown
        self.schedule = make_schedule(options.seed, options.duration_s, scenario, options.netns)
        self.checker = Checker(scenario.fleet.reserve_fraction)
        self.applied: list[Applied] = []
        self.rejected: dict[str, str] = {}
        self._unsure: dict[str, dict[str, Any]] = {}  # action id -> body, outcome unknown
        self._heals: list[tuple[float, int, Callable[[], object]]] = []
        self._context: Context | None = None  # what the appliers of injections.py act on
        self._t0 = 0.0
        self.timeline = Timeline(self._now)

    def run(self) -> ChaosResult:
        """Start the fleet, inject, check, drain; the result (never raises on a violation)."""
        opts = self.options
        run_options = RunOptions(speedup=opts.speedup, run_dir=opts.run_dir)
        fleet = NetnsRun if opts.netns else LocalRun
        with fleet(self.scenario, run_options) as run:
            faults = ProcessFaults(run)
            http = run.http(timeout_s=4.0)
            try:
                samples, actions = self._loop(run, faults, http)
                events = self._event_counts(run)
            finally:
                self.timeline.close()
                faults.heal_all()
                http.close()
        return ChaosResult(
            options=opts,
            run_dir=run.run_dir,
            applied=self.applied,
            checker=self.checker,
            actions=actions,
            rejected=self.rejected,
            event_counts=events,
            samples=samples,
            wall_s=self._now(),
        )

    # -- the loop -------------------------------------------------------------------

    def _loop(
        self, run: LocalRun | NetnsRun, faults: ProcessFaults, http: httpx.Client
    ) -> tuple[int, list[dict[str, Any]] | None]:
        opts = self.options
        scripted = []
        if opts.scenario_actions:
            for a in sorted(self.scenario.actions, key=lambda a: a.at_s):
                body = {**msgspec.to_builtins(a.action), "action_id": a.id}
                body["request_id"] = f"chaos-{opts.seed}-scenario-{a.id}"
                scripted.append((a.at_s / opts.speedup, body))
        pending = list(self.schedule)
        self._t0 = time.monotonic()
        samples, next_sample, next_retry = 0, 0.0, 0.0
        actions: list[dict[str, Any]] | None = None
        while not self.shutdown.is_set():
            now = self._now()
            while scripted and scripted[0][0] <= now:
                self._submit(http, scripted.pop(0)[1])
            while pending and pending[0].at_s <= now and now < opts.duration_s:
                self._apply(pending.pop(0), run, faults, http)
            while self._heals and self._heals[0][0] <= now:
                heapq.heappop(self._heals)[2]()
            if self._unsure and now >= next_retry:
                for body in list(self._unsure.values()):
                    self._submit(http, body)
                next_retry = now + RETRY_EVERY_S
            if now >= next_sample:
                actions = self._sample(run, http)
                samples += 1
                next_sample = now + SAMPLE_EVERY_S
                if now >= opts.duration_s and self._settled(actions, scripted):
                    break
            if now >= opts.duration_s + opts.drain_s:
                break
            self.shutdown.wait(0.05)
        self.timeline.close()  # a shutdown or the drain deadline: heal what is still broken
        while self._heals:
            heapq.heappop(self._heals)[2]()
        final = self._final(http)
        self.checker.finish(self._now(), final)
        return samples, final if final is not None else actions

    def _final(self, http: httpx.Client) -> list[dict[str, Any]] | None:
        """The last action list; the gateway may need a moment after a heal."""
        deadline = self._now() + FINAL_WAIT_S
        while (final := self._get(http, "/v1/actions")) is None and self._now() < deadline:
            time.sleep(0.25)
        return final

    def _settled(self, actions: list[dict[str, Any]] | None, scripted: list[Any]) -> bool:
        if actions is None or scripted or self._unsure or self._heals or self.timeline.pending():
            return False
        states = {r["action_id"]: r["state"] for r in actions}
        return all(states.get(a) in TERMINAL for a in self.checker.accepted_at)

    def _now(self) -> float:
        return time.monotonic() - self._t0

    # -- injections --------------------------------------------------------------------

    def _apply(
        self,
        injection: Injection,
        run: LocalRun | NetnsRun,
        faults: ProcessFaults,
        http: httpx.Client,
    ) -> None:
        applied = Applied(injection, self._now())
        self.applied.append(applied)
        log.info("inject %s", injection.describe())
        kind, target = injection.kind, injection.target
        if kind in CUTS:
            self._cut(injection, applied, faults)
        elif kind == "replan_kill_router":
            self._replan_kill(injection, applied, faults, http)
        elif kind in {"kill_agent", "kill_gs", "kill_router"}:
            name = {"kill_gs": "ground-station", "kill_router": "router"}.get(
                kind, f"agent-{target}"
            )
            faults.kill(name)
            if kind == "kill_agent":
                self.checker.excuse(target, "agent killed")
            self._later(injection, applied, lambda: self._restart(faults, name, applied))
        elif kind == "battery":
            body = {"type": "battery", "uav_id": target, "fraction": injection.params["fraction"]}
            self.checker.excuse(target, f"battery fault {injection.params['fraction']:.2f}")
            try:
                response = http.post("/v1/sim/faults", json=body)
                applied.note = f"HTTP {response.status_code}"
            except httpx.HTTPError as exc:
                applied.note = f"not applied: {exc}"
        elif kind in APPLIERS:
            if self._context is None:
                self._context = Context(
                    run=run,
                    faults=faults,
                    http=http,
                    checker=self.checker,
                    speedup=self.options.speedup,
                    now=self._now,
                    submit=lambda body: self._submit(http, body),
                )
            heal = APPLIERS[kind](injection, self._context, applied)
            if heal is not None:
                self._later(injection, applied, heal)
        else:
            applied.note = self._submit(http, dict(injection.params))

    def _later(self, injection: Injection, applied: Applied, heal: Callable[[], None]) -> None:
        def healed() -> None:
            heal()
            applied.healed_s = self._now()

        due = applied.at_s + injection.hold_s
        heapq.heappush(self._heals, (due, len(self.applied), healed))

    def _cut(self, injection: Injection, applied: Applied, faults: ProcessFaults) -> None:
        """Partition the target once, or in a burst of short cuts, on the timeline.
        A frozen agent cannot land on its own: a later dip below reserve is excused."""
        name = process_name(injection.target)
        if not faults.real_cuts and name.startswith("agent-"):
            self.checker.excuse(injection.target, f"frozen within {injection.hold_s:.1f} s")

        def heal() -> None:
            faults.heal(name)
            applied.healed_s = self._now()

        for offset, hold in injection.params.get("cuts") or [[0.0, injection.hold_s]]:
            self.timeline.at(applied.at_s + offset, lambda: faults.cut(name))
            self.timeline.at(applied.at_s + offset + hold, heal)

    def _replan_kill(
        self, injection: Injection, applied: Applied, faults: ProcessFaults, http: httpx.Client
    ) -> None:
        """Submit the action, ``kill -9`` the router ``kill_after_s`` after the
        answer (while the ground station replans), restart it ``down_s`` later.
        Both on the loop: a child must be started on the main thread (its
        PR_SET_PDEATHSIG follows the thread that started it)."""
        params = injection.params
        applied.note = self._submit(http, dict(params["action"]))
        kill_at = self._now() + params["kill_after_s"]

        def restart() -> None:
            child = faults.restart("router")
            applied.note += f"; router restarted as pid {child.popen.pid}"
            applied.healed_s = self._now()

        order = len(self.applied)
        heapq.heappush(self._heals, (kill_at, order, lambda: faults.kill("router")))
        heapq.heappush(self._heals, (kill_at + params["down_s"], order, restart))

    def _restart(self, faults: ProcessFaults, name: str, applied: Applied) -> None:
        child = faults.restart(name)
        applied.note = f"restarted as pid {child.popen.pid}"

    # -- REST ------------------------------------------------------------------------

    def _submit(self, http: httpx.Client, body: dict[str, Any]) -> str:
        """POST an action; remember it as accepted, rejected or unsure."""
        action_id = body["action_id"]
        try:
            response = http.post("/v1/actions", json=body)
        except httpx.HTTPError as exc:
            self._unsure[action_id] = body
            return f"unsure ({type(exc).__name__}), will retry"
        if response.status_code < 300:
            self._unsure.pop(action_id, None)
            self.checker.accepted(action_id, self._now())
            return "accepted"
        if response.status_code >= 500:
            self._unsure[action_id] = body
            return f"unsure (HTTP {response.status_code}), will retry"
        self._unsure.pop(action_id, None)
        self.rejected[action_id] = f"HTTP {response.status_code}: {response.text[:120]}"
        return f"rejected (HTTP {response.status_code})"

    def _get(self, http: httpx.Client, path: str) -> Any:
        try:
            response = http.get(path)
        except httpx.HTTPError:
            return None
        return response.json() if response.status_code == 200 else None

    def _sample(self, run: LocalRun | NetnsRun, http: httpx.Client) -> list[dict[str, Any]] | None:
        actions = self._get(http, "/v1/actions")
        plans = self._get(http, "/v1/plan")
        fleet = self._get(http, "/v1/fleet")
        truth: SimState | None = None
        if run.bus is not None:
            try:
                truth = run.bus.query(run.keys.sim("state"), GetSimState(), SimState, 2.0)
            except LinecrewError:
                truth = None
        self.checker.sample(self._now(), actions, plans, fleet, truth)
        return actions

    def _event_counts(self, run: LocalRun | NetnsRun) -> dict[str, int]:
        if run.bus is None:
            return {}
        try:
            history = run.bus.query(
                run.keys.rpc("history"), GetHistory(limit=10000), HistoryReply, 5.0
            )
        except LinecrewError:
            return {}
        counts: dict[str, int] = {}
        for event in history.events:
            counts[event.kind] = counts.get(event.kind, 0) + 1
        return counts
