"""The chaos schedule: every injection of a run, decided up front by one
``random.Random(seed)`` so that a seed names exactly one schedule (what,
on which target, when, for how long, with which parameters).

Times are wall seconds since the chaos phase started. Disruptions
(partitions of an agent or a ground process, bursts of short cuts, kills, a
router kill right after a new action's answer (during its replan), the
store's disk made read-only, an agent restarted on a wrong clock) never
overlap each other, so every disruption's effect can be
told apart in the report (and a ground station is never restarted onto a
disk it cannot write); battery, motor and GPS faults, new actions, cancels
and edits fall anywhere, including inside a disruption. Cancels and edits
name one of the two latest chaos actions; at most one motor fault brings a UAV down, so
the others can take over its work.
"""

from __future__ import annotations

import dataclasses
import random
from collections.abc import Callable
from typing import Any

from linecrew.chaos.cuts import burst, cut_target
from proto.scenario import Scenario

DISRUPTIONS = frozenset(
    {"partition", "cut_burst", "kill_agent", "kill_gs", "kill_router", "replan_kill_router"}
    | {"disk", "clock_jump"}
)
UAV_TARGETED = frozenset({"kill_agent", "clock_jump"})
CUTS = frozenset({"partition", "cut_burst"})  # target: a UAV id or a ground process

# kind -> relative weight of being picked at each step
WEIGHTS: dict[str, float] = {
    "partition": 3.0,
    "cut_burst": 1.0,
    "kill_agent": 1.0,
    "kill_gs": 1.0,
    "kill_router": 0.5,
    "replan_kill_router": 0.5,
    "battery": 1.5,
    "action": 2.5,
    "cancel": 0.8,
    "edit": 1.0,
    "motor": 0.4,
    "gps": 1.0,
    "disk": 1.0,
    "clock_jump": 0.8,
}


@dataclasses.dataclass(frozen=True, kw_only=True)
class Injection:
    """One thing the runner does to the fleet."""

    at_s: float  # wall seconds since the chaos phase started
    kind: str  # a key of WEIGHTS
    target: str = ""  # a UAV id (kill_agent, battery, motor, gps, clock_jump), a UAV
    # id or ground process (partition, cut_burst), an action id (cancel, edit); else ""
    hold_s: float = 0.0  # wall seconds until healed / restarted / re-checked
    params: dict[str, Any] = dataclasses.field(default_factory=dict)

    def describe(self) -> str:
        """One line for the report."""
        what = {
            "partition": f"partition {self.target} for {self.hold_s:.1f} s",
            "cut_burst": f"cut {self.target} {len(self.params.get('cuts', []))} times "
            f"({', '.join(f'{h:.1f}' for _, h in self.params.get('cuts', []))} s) "
            f"within {self.hold_s:.1f} s",
            "kill_agent": f"kill -9 agent {self.target}, restart after {self.hold_s:.1f} s",
            "kill_gs": f"kill -9 ground station, restart after {self.hold_s:.1f} s",
            "kill_router": f"kill -9 router, restart after {self.hold_s:.1f} s",
            "replan_kill_router": f"new action {self.params.get('action', {}).get('action_id')}"
            f", kill -9 router {self.params.get('kill_after_s', 0):.2f} s after its answer, "
            f"restart {self.params.get('down_s', 0):.1f} s later",
            "battery": f"battery of {self.target} to {self.params.get('fraction', 0):.2f}",
            "action": f"new action {self.params.get('action_id', '')} "
            f"({self.params.get('type', '')})",
            "cancel": f"cancel {self.target}",
            "edit": f"edit {self.target}: {_change(self.params.get('change', {}))}",
            "motor": f"motors of {self.target} fail",
            "gps": f"GPS of {self.target} frozen for {self.hold_s:.1f} s",
            "disk": f"store's disk read-only for {self.hold_s:.1f} s, probe action "
            f"{self.params.get('action_id', '')}",
            "clock_jump": f"restart agent {self.target} with its clock "
            f"{self.params.get('offset_s', 0):+.0f} mission s off, back after {self.hold_s:.1f} s",
        }
        return what.get(self.kind, self.kind)


def make_schedule(
    seed: int,
    duration_s: float,
    scenario: Scenario,
    netns: bool = False,
    mix: dict[str, float] | None = None,
) -> list[Injection]:
    """The injections of a run of ``duration_s`` wall seconds on ``scenario``'s
    fleet; ``netns``: partitions are real cuts (the gateway may be cut too);
    ``mix``: other weights than :data:`WEIGHTS` (a focused run).
    Pure: the same arguments give the same list."""
    rng = random.Random(seed)
    drawing = _Drawing(
        rng=rng,
        seed=seed,
        scenario=scenario,
        uavs=[u.id for u in scenario.fleet.uavs],
        netns=netns,
        used_tools={a.action.tool for a in scenario.actions if hasattr(a.action, "tool")},
    )
    mix = WEIGHTS if mix is None else mix
    kinds = sorted(k for k in mix if mix[k] > 0)
    weights = [mix[k] for k in kinds]
    schedule: list[Injection] = []
    t = rng.uniform(3.0, 6.0)
    disruption_free_s = 0.0  # when the last disruption has healed
    while t < duration_s:
        kind = rng.choices(kinds, weights)[0]
        if kind in DISRUPTIONS:
            t = max(t, disruption_free_s + rng.uniform(2.0, 5.0))
            if t >= duration_s:
                break
            disruption = _disruption(drawing, kind, round(t, 2))
            disruption_free_s = t + disruption.hold_s
            schedule.append(disruption)
        else:
            drawn = _OTHERS.get(kind, _new_action)(drawing, kind, round(t, 2))
            if drawn is None:
                continue  # the draw is spent; the next one picks again at the same time
            schedule.append(drawn)
        t += rng.uniform(1.5, 6.0)
    return schedule


@dataclasses.dataclass(kw_only=True)
class _Drawing:
    """What the draws of one schedule share: its random stream and fleet, and
    what earlier draws decided that later ones depend on."""

    rng: random.Random
    seed: int
    scenario: Scenario
    uavs: list[str]
    netns: bool
    used_tools: set[str]  # the scenario's and chaos deliveries' tools: each goes once
    serial: int = 0  # of the last chaos action
    # chaos action id -> its body
    submitted: dict[str, dict[str, Any]] = dataclasses.field(default_factory=dict)
    fallen: bool = False  # a motor fault was scheduled

    def action_body(self) -> dict[str, Any]:
        """The body of a new chaos action, under the next serial."""
        self.serial += 1
        action_id = f"chaos-{self.seed}-{self.serial}"
        return _random_action(self.rng, self.scenario, action_id, self.used_tools)


def _disruption(d: _Drawing, kind: str, at_s: float) -> Injection:
    """One of :data:`DISRUPTIONS` at ``at_s``; its ``hold_s`` is how long it
    lasts (until healed, restarted or its probe re-checked)."""
    rng = d.rng
    hold = _hold_s(rng, kind)
    target = rng.choice(d.uavs) if kind in UAV_TARGETED else ""
    params: dict[str, Any] = {}
    if kind in CUTS:
        target = cut_target(rng, d.uavs, d.netns)
    if kind == "cut_burst":
        params = {"cuts": burst(rng)}
        hold = round(sum(params["cuts"][-1]), 2)
    elif kind == "replan_kill_router":
        action = d.action_body()
        kill_after = round(rng.uniform(0.05, 0.5), 2)
        params = {"action": action, "kill_after_s": kill_after, "down_s": hold}
        hold = round(kill_after + hold, 2)
    elif kind == "clock_jump":
        params = {"offset_s": rng.choice([-1, 1]) * round(rng.uniform(2.0, 30.0))}
    elif kind == "disk":
        params = d.action_body()
    return Injection(at_s=at_s, kind=kind, target=target, hold_s=hold, params=params)


def _battery(d: _Drawing, kind: str, at_s: float) -> Injection:
    """A UAV's battery drops to a fraction between 0.3 and 0.7."""
    fraction = round(d.rng.uniform(0.3, 0.7), 2)
    return Injection(
        at_s=at_s, kind=kind, target=d.rng.choice(d.uavs), params={"fraction": fraction}
    )


def _gps(d: _Drawing, kind: str, at_s: float) -> Injection:
    """A UAV's GPS frozen for 0.5 to 3 s."""
    hold = round(d.rng.uniform(0.5, 3.0), 2)
    return Injection(at_s=at_s, kind=kind, target=d.rng.choice(d.uavs), hold_s=hold)


def _motor(d: _Drawing, kind: str, at_s: float) -> Injection | None:
    """A UAV's motors fail; None (the draw is spent) once one has, or with a
    single UAV, so that another can always take over its work."""
    if d.fallen or len(d.uavs) < 2:
        return None
    d.fallen = True
    return Injection(at_s=at_s, kind=kind, target=d.rng.choice(d.uavs))


def _amend(d: _Drawing, kind: str, at_s: float) -> Injection | None:
    """A cancel or an edit of one of the two latest chaos actions (likely
    still live); None (the draw is spent) before the first one."""
    if not d.submitted:
        return None
    action_id = d.rng.choice(list(d.submitted)[-2:])
    params = {"change": _edit(d.rng, d.submitted[action_id])} if kind == "edit" else {}
    hold = round(d.rng.uniform(2.0, 6.0), 2)
    return Injection(at_s=at_s, kind=kind, target=action_id, hold_s=hold, params=params)


def _new_action(d: _Drawing, kind: str, at_s: float) -> Injection:
    """A new chaos action, remembered for later cancels and edits."""
    params = d.action_body()
    d.submitted[params["action_id"]] = params
    return Injection(at_s=at_s, kind=kind, params=params)


_OTHERS: dict[str, Callable[[_Drawing, str, float], Injection | None]] = {
    "battery": _battery,
    "gps": _gps,
    "motor": _motor,
    "cancel": _amend,
    "edit": _amend,
}
"""Draws of the kinds that are not disruptions (any other kind: a new action)."""


def _edit(rng: random.Random, body: dict[str, Any]) -> dict[str, Any]:
    """A PATCH body for the action submitted as ``body``: a monitoring's new
    duration (the whole action), else a new priority."""
    if body["type"] == "monitor" and rng.random() < 0.6:
        action = {k: v for k, v in body.items() if k not in {"action_id", "request_id"}}
        return {"action": action | {"duration_s": round(rng.uniform(20, 90))}}
    return {"priority": rng.randint(1, 5)}


def _change(change: dict[str, Any]) -> str:
    """The report's words for an edit."""
    if "action" in change:
        return f"duration {change['action'].get('duration_s', 0):g} s"
    return f"priority {change.get('priority', '')}"


def _hold_s(rng: random.Random, kind: str) -> float:
    """Partitions: a third shorter than the agents' 3 s grace, a third between
    the agents' and the ground station's (3-5 s), a third well past both."""
    if kind == "partition":
        band = rng.choice([(0.5, 2.5), (3.2, 4.6), (6.0, 10.0)])
        return round(rng.uniform(*band), 2)
    if kind == "kill_agent":
        return round(rng.uniform(1.0, 6.0), 2)
    if kind == "kill_gs":
        return round(rng.uniform(0.5, 4.0), 2)
    if kind == "disk":
        return round(rng.uniform(2.0, 6.0), 2)
    if kind == "clock_jump":
        return round(rng.uniform(3.0, 8.0), 2)
    return round(rng.uniform(0.5, 3.0), 2)


def _random_action(
    rng: random.Random, scenario: Scenario, action_id: str, used_tools: set[str]
) -> dict[str, Any]:
    """A small REST action body: an inspection near a tower, a short monitoring
    or a delivery of a tool still at its station (each tool goes once; a
    delivered tool stays with its worker), sized for a few wall seconds at x10."""
    site = scenario.site
    kind = rng.choice(["inspect", "inspect", "monitor", "deliver"])
    stations = [
        (s, t.name) for s in site.tool_stations for t in s.tools if t.name not in used_tools
    ]
    if kind == "deliver" and not stations:
        kind = "inspect"
    body: dict[str, Any] = {"action_id": action_id, "request_id": f"req-{action_id}"}
    if kind == "inspect":
        tower = rng.choice(site.towers).position
        waypoints = [
            {
                "position": {
                    "x_m": round(tower.x_m + rng.uniform(-6, 6), 1),
                    "y_m": round(tower.y_m + rng.uniform(-6, 6), 1),
                    "z_m": round(max(3.0, tower.z_m + rng.uniform(-5, 2)), 1),
                },
                "service_s": round(rng.uniform(2, 6), 1),
            }
            for _ in range(rng.randint(1, 4))
        ]
        body |= {"type": "inspect", "priority": rng.randint(1, 3), "waypoints": waypoints}
    elif kind == "monitor":
        body |= {
            "type": "monitor",
            "worker_id": rng.choice(site.workers).id,
            "uavs": 1,
            "standoff_m": 4.0,
            "duration_s": round(rng.uniform(30, 90)),
            "priority": rng.randint(1, 3),
        }
    else:
        station, tool = rng.choice(stations)
        used_tools.add(tool)
        body |= {
            "type": "deliver",
            "tool": tool,
            "tool_station_id": station.id,
            "worker_id": rng.choice(site.workers).id,
            "priority": rng.randint(1, 3),
        }
    return body
