"""What really happened, from the simulator: a sampler of its ground truth
(``sim/state``) and the measures the live-mission tests assert on.

Nothing here asks the ground station what it believes; the gateway is used
only to submit actions and to wait for them to end.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from collections.abc import Callable

from linecrew.client.gateway import GatewayError
from linecrew.launch.local_run import LocalRun
from proto import GetHistory, GetSimState, GsEvent, HistoryReply, Point, SimState
from tests.support.processes import wait_until

TERMINAL = {"completed", "failed", "cancelled"}
SLOT_TOLERANCE_M = 1.5
"""How far from its stand-off point a hovering UAV still counts as watching."""


@dataclasses.dataclass(frozen=True)
class Sample:
    """One reading of the simulator's truth."""

    sim_s: float
    state: SimState


class TruthLog:
    """Samples the simulator while a test waits, and measures the samples."""

    def __init__(self, run: LocalRun) -> None:
        self.run = run
        self.gateway = run.gateway()
        self.samples: list[Sample] = []

    def sample(self) -> SimState:
        assert self.run.bus is not None
        state = self.run.bus.query(self.run.keys.sim("state"), GetSimState(), SimState, 5.0)
        self.samples.append(Sample(state.sim_time_s, state))
        return state

    def until(self, what: str, predicate: Callable[[], object], timeout_s: float) -> object:
        """Sample every 0.2 s until ``predicate()`` is truthy; its value."""
        seen: list[object] = [None]

        def sampled() -> object:
            self.sample()
            seen[0] = predicate()
            return seen[0]

        wait_until(sampled, timeout_s, what, period_s=0.2)
        return seen[0]

    # -- the operator's side, only to drive the test ---------------------------------

    def submit(self, body: dict) -> dict:
        return self.gateway.call("POST", "/v1/actions", json=body)

    def action(self, action_id: str) -> dict:
        return self.gateway.call("GET", f"/v1/actions/{action_id}")

    def finished(self, *action_ids: str) -> bool:
        """Whether the actions ended; not yet while the ground station is
        busy catching up (a 503, as documented) after a fault."""
        try:
            return all(self.action(a)["state"] in TERMINAL for a in action_ids)
        except GatewayError as exc:
            if exc.status == 503:
                return False
            raise

    def working_on(self, action_id: str) -> set[str]:
        """The UAVs whose agents report a task of ``action_id`` as theirs now
        (a UAV only passing through a worker's ring is not among them)."""
        fleet = self.gateway.call("GET", "/v1/fleet")
        tasks = {u["uav_id"]: (u.get("status") or {}).get("task_id") or "" for u in fleet}
        return {uav for uav, task in tasks.items() if task.startswith(f"{action_id}.")}

    def events(self) -> list[GsEvent]:
        assert self.run.bus is not None
        reply = self.run.bus.query(
            self.run.keys.rpc("history"), GetHistory(limit=5000), HistoryReply, 5.0
        )
        return reply.events

    # -- measures -------------------------------------------------------------------------

    def watching(self, sample: Sample, worker: Point, standoff_m: float, height_m: float) -> set:
        """The UAVs flying at the stand-off ring around ``worker`` in ``sample``."""
        out = set()
        for v in sample.state.vehicles:
            p = v.position
            ring = math.hypot(p.x_m - worker.x_m, p.y_m - worker.y_m)
            high = p.z_m - worker.z_m
            if (
                v.state == "flying"
                and abs(ring - standoff_m) <= SLOT_TOLERANCE_M
                and abs(high - height_m) <= SLOT_TOLERANCE_M
            ):
                out.add(v.uav_id)
        return out

    def coverage(
        self, worker: Point, standoff_m: float, height_m: float, k: int
    ) -> tuple[float, float]:
        """(seconds with at least ``k`` UAVs watching, longest gap in seconds
        between the first and the last such moment)."""
        covered, gap, longest = 0.0, 0.0, 0.0
        started = False
        for a, b in itertools.pairwise(self.samples):
            dt = b.sim_s - a.sim_s
            if len(self.watching(a, worker, standoff_m, height_m)) >= k:
                covered += dt
                started = True
                longest = max(longest, gap)
                gap = 0.0
            elif started:
                gap += dt
        return covered, longest

    def watchers(self, worker: Point, standoff_m: float, height_m: float) -> set[str]:
        """Every UAV that was ever seen watching ``worker``."""
        seen: set[str] = set()
        for s in self.samples:
            seen |= self.watching(s, worker, standoff_m, height_m)
        return seen

    def violations(self, *kinds: str) -> list:
        last = self.samples[-1].state if self.samples else self.sample()
        return [v for v in last.violations if v.kind in kinds]
