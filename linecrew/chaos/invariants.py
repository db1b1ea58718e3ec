"""The invariants a chaos run checks on every sample, and at the end.

- ``action_lost``: every action the gateway accepted (2xx) is listed by the
  ground station whenever it answers.
- ``double_task``: no piece of work is in two UAVs' current plans at once
  (an inspection waypoint, a pick-up or drop; a monitoring slot only if two
  UAVs cover it for longer than a hand-over), no two present UAVs report
  executing the same such task on two consecutive samples, and (the
  simulator's truth) no two UAVs hover at one spot watching the same worker
  for longer than a hand-over: both credited watching it since the last
  sample, flying, closer than ``SAME_SPOT_M`` horizontally.
- ``below_reserve``: no vehicle (the simulator's truth) falls below the
  fleet's reserve fraction, unless a fault injected on it (battery fault,
  freeze, kill) made the reserve impossible: then it is reported as excused.
- ``unsafe``: the simulator records no safety violation (two UAVs closer
  than the separation, a UAV near a person, a landing off every spot, a
  crash); a crash of a UAV a fault was injected on is reported as excused.
- ``overcredited``: no worker's recorded monitoring (each monitor action's
  ``monitored_s`` times its UAVs) exceeds the seconds the simulator saw
  UAVs hover watching that worker, beyond ``CREDIT_TOLERANCE`` and
  ``CREDIT_SLACK_S`` per UAV of each action (settling at the slot).
- ``unfinished``: at the end every accepted action has completed or failed,
  unless it waits for a capable UAV (its reason ``no_capable_uav``) and a
  UAV crashed after a fault injected on it (excused: a crashed UAV needs a
  person); ``failed_without_reason``: a failed action carries a reason.

The checker only consumes samples (plain dicts from the REST gateway and the
simulator's :class:`proto.SimState`); it does no I/O and reads no clock.
"""

from __future__ import annotations

import collections
import dataclasses
import itertools
import math
from typing import Any

from proto import Point, SimState

TERMINAL = frozenset({"completed", "failed", "cancelled"})
HANDOVER_S = 30.0  # mission seconds two monitoring segments of one slot may overlap
# status task ids that name UAV-scoped work (never shared by construction)
_OWN_TASKS = ("recharge", "wait", "home")
EXECUTING_TWICE_S = 3.0
"""Wall seconds two UAVs' statuses must name one task at once to count as
doing it twice: longer than a killed agent's last status takes to fall
silent (a replan may give its task to another meanwhile; chaos seed 12)."""
CREDIT_TOLERANCE = 0.02  # recorded monitoring may exceed the watched seconds by this share
CREDIT_SLACK_S = 5.0  # and by this many seconds per UAV of each monitor action
SAME_SPOT_M = 2.0  # two watching UAVs this near hold one spot (slots, holds, asides: >= 3 m)


@dataclasses.dataclass(frozen=True)
class Violation:
    """One broken invariant."""

    at_s: float  # wall seconds since the chaos phase started
    invariant: str
    detail: str


class Checker:
    """Feed it :meth:`accepted`, :meth:`excuse`, :meth:`sample`, then :meth:`finish`."""

    def __init__(self, reserve_fraction: float, tolerance: float = 0.03) -> None:
        self.reserve_fraction = reserve_fraction
        self.tolerance = tolerance
        self.accepted_at: dict[str, float] = {}
        self.excuses: dict[str, list[str]] = collections.defaultdict(list)
        self.violations: list[Violation] = []
        self.excused: list[str] = []  # below-reserve episodes a fault explains
        self.checks: collections.Counter[str] = collections.Counter()
        self._below: set[str] = set()  # UAVs currently below reserve (one report per episode)
        self._executing_twice: dict[str, float] = {}  # task id -> seen doubled since
        self._seen: set[tuple[str, str]] = set()  # (invariant, detail) already reported
        self._unsafe_seen = 0  # the simulator's violations already judged
        self._overcredited: set[str] = set()  # workers already reported
        self._watched: dict[tuple[str, str], float] = {}  # (worker, uav) -> watched s, last sample
        self._together: dict[tuple[str, str, str], float] = {}  # (worker, uav, uav) -> since sim s
        self._crashed: set[str] = set()  # UAVs the simulator saw crashed after a fault

    # -- inputs ------------------------------------------------------------------

    def accepted(self, action_id: str, at_s: float) -> None:
        """The gateway accepted ``action_id`` (2xx) at ``at_s``."""
        self.accepted_at.setdefault(action_id, at_s)

    def excuse(self, uav_id: str, why: str) -> None:
        """A fault was injected on ``uav_id``: a later dip below reserve is excused."""
        self.excuses[uav_id].append(why)

    def sample(
        self,
        at_s: float,
        actions: list[dict[str, Any]] | None,
        plans: list[dict[str, Any]] | None,
        fleet: list[dict[str, Any]] | None,
        truth: SimState | None,
    ) -> None:
        """Check one sample; ``None`` where that source did not answer."""
        if actions is not None:
            self._check_lost(at_s, actions)
        if plans is not None:
            self._check_plans(at_s, plans)
        if fleet is not None:
            self._check_executing(at_s, fleet)
        if truth is not None:
            self._crashed |= {
                v.uav_id
                for v in truth.vehicles
                if v.state == "crashed" and self.excuses.get(v.uav_id)
            }
            self._check_reserve(at_s, truth)
            self._check_safety(at_s, truth)
            self._check_one_spot(at_s, truth)
            if actions is not None:  # the truth was read after the actions
                self._check_credit(at_s, actions, truth)

    def finish(self, at_s: float, actions: list[dict[str, Any]] | None) -> None:
        """The end-of-run checks on the final action list."""
        if actions is None:
            self._violate(at_s, "unfinished", "the ground station did not answer at the end")
            return
        self._check_lost(at_s, actions)
        by_id = {r["action_id"]: r for r in actions}
        for action_id in sorted(self.accepted_at):
            record = by_id.get(action_id)
            if record is None:
                continue  # already reported as lost
            self.checks["unfinished"] += 1
            if record["state"] not in TERMINAL and self._waits_for_crashed(record):
                self.excused.append(
                    f"t={at_s:.1f} s {action_id} still {record['state']}, waiting for a capable"
                    f" UAV: excused by the crash of {', '.join(sorted(self._crashed))}"
                )
            elif record["state"] not in TERMINAL:
                self._violate(
                    at_s,
                    "unfinished",
                    f"{action_id} still {record['state']} "
                    f"({100 * record.get('progress', 0):.0f} %)",
                )
            elif record["state"] == "failed":
                self.checks["failed_without_reason"] += 1
                if not record.get("reason"):
                    self._violate(at_s, "failed_without_reason", action_id)

    def _waits_for_crashed(self, record: dict[str, Any]) -> bool:
        """Whether ``record`` waits for a capable UAV while one a fault was
        injected on lies crashed."""
        return "no_capable_uav" in (record.get("reason") or "") and bool(self._crashed)

    # -- checks ------------------------------------------------------------------

    def _check_lost(self, at_s: float, actions: list[dict[str, Any]]) -> None:
        listed = {r["action_id"] for r in actions}
        self.checks["action_lost"] += 1
        for action_id in sorted(set(self.accepted_at) - listed):
            self._violate(at_s, "action_lost", f"{action_id} accepted but not listed")

    def _check_plans(self, at_s: float, plans: list[dict[str, Any]]) -> None:
        self.checks["double_task"] += 1
        owners: dict[str, set[str]] = collections.defaultdict(set)
        slots: dict[str, list[tuple[float, float, str]]] = collections.defaultdict(list)
        for plan in plans:
            uav = plan["uav_id"]
            for task in plan.get("tasks", []):
                for key in _work_keys(task):
                    owners[key].add(uav)
                if task["type"] == "monitor":
                    slot = f"{task['action_id']}/slot{task['slot']}"
                    slots[slot].append((task["start_s"], task["end_s"], uav))
        for key, uavs in sorted(owners.items()):
            if len(uavs) > 1:
                self._violate(at_s, "double_task", f"{key} planned for {sorted(uavs)}")
        for slot, segments in sorted(slots.items()):
            segments.sort()
            for (s1, e1, u1), (s2, e2, u2) in itertools.pairwise(segments):
                overlap = min(e1, e2) - max(s1, s2)
                if u1 != u2 and overlap > HANDOVER_S:
                    self._violate(
                        at_s,
                        "double_task",
                        f"{slot} covered by {u1} and {u2} for {overlap:.0f} s at once",
                    )

    def _check_executing(self, at_s: float, fleet: list[dict[str, Any]]) -> None:
        self.checks["double_task"] += 1
        doers: dict[str, list[str]] = collections.defaultdict(list)
        for uav in fleet:
            status = uav.get("status") or {}
            task_id = status.get("task_id")
            if uav.get("state") in {"lost", "failed"} or not task_id:
                continue
            if uav.get("silent_since_s") is not None:
                continue  # its tasks are unknown: its last status is no evidence
            if status.get("state") != "busy" or task_id.startswith(uav["uav_id"] + "."):
                continue
            if ".slot" in task_id or any(task_id.endswith(k) for k in _OWN_TASKS):
                continue  # monitoring hands over; own tasks are never shared
            doers[task_id].append(uav["uav_id"])
        doubled = {t for t, uavs in doers.items() if len(uavs) > 1}
        self._executing_twice = {t: self._executing_twice.get(t, at_s) for t in doubled}
        for task_id, since in sorted(self._executing_twice.items()):
            if at_s - since >= EXECUTING_TWICE_S:
                detail = f"{task_id} executed by {sorted(doers[task_id])}"
                self._violate(at_s, "double_task", detail)

    def _check_reserve(self, at_s: float, truth: SimState) -> None:
        self.checks["below_reserve"] += 1
        floor = self.reserve_fraction - self.tolerance
        for vehicle in truth.vehicles:
            uav = vehicle.uav_id
            if vehicle.battery_fraction >= floor or vehicle.state == "crashed":
                self._below.discard(uav)
                continue
            if uav in self._below:
                continue
            self._below.add(uav)
            where = f"{uav} at {100 * vehicle.battery_fraction:.0f} % ({vehicle.state})"
            if self.excuses.get(uav):
                self.excused.append(
                    f"t={at_s:.1f} s {where}: excused by {', '.join(self.excuses[uav])}"
                )
            else:
                self._violate(at_s, "below_reserve", where)

    def _check_safety(self, at_s: float, truth: SimState) -> None:
        self.checks["unsafe"] += 1
        for v in truth.violations[self._unsafe_seen :]:
            where = f"{v.kind} {v.uav_id} {v.detail} at sim {v.sim_time_s:.1f} s".replace("  ", " ")
            if v.kind == "ground_contact" and self.excuses.get(v.uav_id):
                self.excused.append(
                    f"t={at_s:.1f} s {where}: excused by {', '.join(self.excuses[v.uav_id])}"
                )
            else:
                self._violate(at_s, "unsafe", where)
        self._unsafe_seen = max(self._unsafe_seen, len(truth.violations))

    def _check_one_spot(self, at_s: float, truth: SimState) -> None:
        """Two UAVs watching one worker from one spot (the simulator's truth)."""
        self.checks["double_task"] += 1
        seconds = {(w.worker_id, w.uav_id): w.seconds for w in truth.watched}
        flying = {v.uav_id: v.position for v in truth.vehicles if v.state == "flying"}
        watching: dict[str, list[str]] = collections.defaultdict(list)
        for (worker, uav), s in sorted(seconds.items()):
            if uav in flying and s > self._watched.get((worker, uav), 0.0):
                watching[worker].append(uav)
        self._watched = seconds
        together = {
            (worker, a, b)
            for worker, uavs in watching.items()
            for a, b in itertools.combinations(uavs, 2)
            if _horizontal(flying[a], flying[b]) <= SAME_SPOT_M
        }
        self._together = {
            pair: self._together.get(pair, truth.sim_time_s) for pair in sorted(together)
        }
        for (worker, a, b), since in self._together.items():
            if truth.sim_time_s - since > HANDOVER_S:
                self._violate(
                    at_s,
                    "double_task",
                    f"{worker} watched by {a} and {b} from one spot for over {HANDOVER_S:.0f} s "
                    f"from sim {since:.0f} s (simulator's truth)",
                )

    def _check_credit(self, at_s: float, actions: list[dict[str, Any]], truth: SimState) -> None:
        self.checks["overcredited"] += 1
        recorded: collections.defaultdict[str, float] = collections.defaultdict(float)
        slack: collections.defaultdict[str, float] = collections.defaultdict(float)
        for record in actions:
            action = record.get("action") or {}
            if action.get("type") != "monitor":
                continue
            uavs = action.get("uavs", 1)
            recorded[action["worker_id"]] += record.get("monitored_s", 0.0) * uavs
            slack[action["worker_id"]] += CREDIT_SLACK_S * uavs
        watched: collections.defaultdict[str, float] = collections.defaultdict(float)
        for w in truth.watched:
            watched[w.worker_id] += w.seconds
        for worker, seconds in sorted(recorded.items()):
            allowed = watched[worker] * (1 + CREDIT_TOLERANCE) + slack[worker]
            if seconds > allowed and worker not in self._overcredited:
                self._overcredited.add(worker)
                self._violate(
                    at_s,
                    "overcredited",
                    f"{worker}: {seconds:.0f} UAV-s of monitoring recorded, "
                    f"{watched[worker]:.0f} s watched",
                )

    def _violate(self, at_s: float, invariant: str, detail: str) -> None:
        if (invariant, detail) in self._seen:
            return
        self._seen.add((invariant, detail))
        self.violations.append(Violation(at_s, invariant, detail))


def _horizontal(p: Point, q: Point) -> float:
    return math.hypot(p.x_m - q.x_m, p.y_m - q.y_m)


def _work_keys(task: dict[str, Any]) -> list[str]:
    """What a task does that only one UAV may do: one key per inspected
    waypoint, the pick-up, the drop."""
    match task["type"]:
        case "inspect":
            return [f"{task['action_id']}/wp{w['index']}" for w in task.get("waypoints", [])]
        case "pick" | "deliver":
            return [task["task_id"]]
    return []
