"""The chaos schedule: every injection of a run, decided up front by one
``random.Random(seed)`` so that a seed names exactly one schedule (what,
on which target, when, for how long, with which parameters).

Times are wall seconds since the chaos phase started. Disruptions
(partitions and kills) never overlap each other, so every disruption's
effect can be told apart in the report; battery faults and new actions fall
anywhere, including inside a disruption.
"""

from __future__ import annotations

import dataclasses
import random
from typing import Any

from proto.scenario import Scenario

DISRUPTIONS = frozenset({"partition", "kill_agent", "kill_gs", "kill_router"})

# kind -> relative weight of being picked at each step
WEIGHTS: dict[str, float] = {
    "partition": 3.0,
    "kill_agent": 1.0,
    "kill_gs": 1.0,
    "kill_router": 1.0,
    "battery": 1.5,
    "action": 2.5,
}


@dataclasses.dataclass(frozen=True, kw_only=True)
class Injection:
    """One thing the runner does to the fleet."""

    at_s: float  # wall seconds since the chaos phase started
    kind: str  # a key of WEIGHTS
    target: str = ""  # a UAV id for partition, kill_agent, battery; "" otherwise
    hold_s: float = 0.0  # partitions and kills: wall seconds until healed / restarted
    params: dict[str, Any] = dataclasses.field(default_factory=dict)

    def describe(self) -> str:
        """One line for the report."""
        what = {
            "partition": f"partition {self.target} for {self.hold_s:.1f} s",
            "kill_agent": f"kill -9 agent {self.target}, restart after {self.hold_s:.1f} s",
            "kill_gs": f"kill -9 ground station, restart after {self.hold_s:.1f} s",
            "kill_router": f"kill -9 router, restart after {self.hold_s:.1f} s",
            "battery": f"battery of {self.target} to {self.params.get('fraction', 0):.2f}",
            "action": f"new action {self.params.get('action_id', '')} "
            f"({self.params.get('type', '')})",
        }
        return what.get(self.kind, self.kind)


def make_schedule(seed: int, duration_s: float, scenario: Scenario) -> list[Injection]:
    """The injections of a run of ``duration_s`` wall seconds on ``scenario``'s
    fleet. Pure: the same arguments give the same list."""
    rng = random.Random(seed)
    uavs = [u.id for u in scenario.fleet.uavs]
    kinds = sorted(WEIGHTS)
    weights = [WEIGHTS[k] for k in kinds]
    schedule: list[Injection] = []
    t = rng.uniform(3.0, 6.0)
    disruption_free_s = 0.0  # when the last disruption has healed
    serial = 0
    used_tools = {a.action.tool for a in scenario.actions if hasattr(a.action, "tool")}
    while t < duration_s:
        kind = rng.choices(kinds, weights)[0]
        if kind in DISRUPTIONS:
            t = max(t, disruption_free_s + rng.uniform(2.0, 5.0))
            if t >= duration_s:
                break
            hold = _hold_s(rng, kind)
            target = rng.choice(uavs) if kind in {"partition", "kill_agent"} else ""
            schedule.append(Injection(at_s=round(t, 2), kind=kind, target=target, hold_s=hold))
            disruption_free_s = t + hold
        elif kind == "battery":
            fraction = round(rng.uniform(0.3, 0.7), 2)
            schedule.append(
                Injection(
                    at_s=round(t, 2),
                    kind=kind,
                    target=rng.choice(uavs),
                    params={"fraction": fraction},
                )
            )
        else:
            serial += 1
            params = _random_action(rng, scenario, f"chaos-{seed}-{serial}", used_tools)
            schedule.append(Injection(at_s=round(t, 2), kind=kind, params=params))
        t += rng.uniform(1.5, 6.0)
    return schedule


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
