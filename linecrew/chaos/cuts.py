"""Partitions in a chaos schedule: which process a cut hits, and the shape
of a burst of short cuts.

A partition's target is a UAV id (its agent is cut off) or the name of a
ground process. On loopback, where a cut is a freeze, the gateway is never
a target: a frozen gateway would stall the observer's own REST calls
instead of cutting the gateway's Zenoh link (see :mod:`linecrew.chaos.faults`).
"""

from __future__ import annotations

import random

FREEZABLE = ("ground-station", "router")  # ground processes cut on loopback too
NETNS_ONLY = ("gateway",)  # ground processes cut only with real cuts
AGENT_SHARE = 0.6  # share of partitions that hit an agent


def cut_target(rng: random.Random, uavs: list[str], netns: bool) -> str:
    """A UAV id (its agent) or a ground process's name."""
    ground = [*FREEZABLE, *(NETNS_ONLY if netns else ())]
    return rng.choice(uavs) if rng.random() < AGENT_SHARE else rng.choice(ground)


def process_name(target: str) -> str:
    """The process a partition of ``target`` cuts off."""
    return target if target in FREEZABLE + NETNS_ONLY else f"agent-{target}"


def burst(rng: random.Random) -> list[list[float]]:
    """3-5 cuts of 0.5-1.5 s, 0.3-1.5 s apart, as ``[offset_s, hold_s]`` pairs
    from the first cut."""
    cuts: list[list[float]] = []
    t = 0.0
    for _ in range(rng.randint(3, 5)):
        hold = round(rng.uniform(0.5, 1.5), 2)
        cuts.append([round(t, 2), hold])
        t += hold + rng.uniform(0.3, 1.5)
    return cuts
